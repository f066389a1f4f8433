// VRPN's wire format, byte by byte: every expected byte is written out by hand from a
// fact of VRPN's sources (docs/vrpn.md names where each comes from), so that a change
// in covtrack's encoder or decoder that would break a real VRPN peer fails here.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "covtrack/vrpn/cookie.hpp"
#include "covtrack/vrpn/framing.hpp"
#include "covtrack/vrpn/message_names.hpp"
#include "covtrack/vrpn/session.hpp"
#include "covtrack/vrpn/system_messages.hpp"
#include "covtrack/vrpn/tracker_address.hpp"
#include "covtrack/vrpn/tracker_report.hpp"

using namespace covtrack;
using namespace covtrack::vrpn;

namespace {

using Bytes = std::vector<std::uint8_t>;

// "00 0a ff" -> {0x00, 0x0a, 0xff}
Bytes hex(const std::string& text) {
  Bytes out;
  for (std::size_t i = 0; i < text.size();) {
    if (text[i] == ' ') {
      ++i;
      continue;
    }
    out.push_back(static_cast<std::uint8_t>(std::stoi(text.substr(i, 2), nullptr, 16)));
    i += 2;
  }
  return out;
}

Bytes ascii(const std::string& text) { return Bytes(text.begin(), text.end()); }

Bytes concat(std::initializer_list<Bytes> parts) {
  Bytes out;
  for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

Bytes framed(const Message& m, std::uint32_t sequence = 0) {
  Bytes out;
  append_message(out, m, sequence);
  return out;
}

}  // namespace

// Fact (vrpn_Connection.C, write_vrpn_cookie and vrpn_COOKIE_SIZE): the 16-character
// version string, two spaces, the remote log mode as an ASCII digit, and zeros up to
// 16 + 8 = 24 bytes (the send buffer is zeroed first).
TEST(VrpnCookie, IsTheVersionTwoSpacesTheLogDigitAndZerosTo24Bytes) {
  const Cookie c = make_cookie();
  const Bytes expected = concat({ascii("vrpn: ver. 07.38"), hex("20 20 30"), hex("00 00 00 00 00")});
  EXPECT_EQ(Bytes(c.begin(), c.end()), expected);
}

// Fact (check_vrpn_cookie): the version must match through its last period; another
// minor version connects with a note; the log digit is '0'-'3'.
TEST(VrpnCookie, AcceptsAnyMinorOfMajorSevenAndRejectsTheRest) {
  auto cookie = [](const std::string& text) {
    Bytes b = ascii(text);
    b.resize(kCookieSize, 0);
    return b;
  };
  auto same = check_cookie(cookie("vrpn: ver. 07.38  0"));
  ASSERT_TRUE(same) << same.error().message;
  EXPECT_FALSE(same->minor_differs);
  auto older = check_cookie(cookie("vrpn: ver. 07.35  2"));
  ASSERT_TRUE(older) << older.error().message;
  EXPECT_TRUE(older->minor_differs);
  EXPECT_EQ(older->version, "vrpn: ver. 07.35");
  EXPECT_EQ(older->log_mode, 2);

  auto major = check_cookie(cookie("vrpn: ver. 06.01  0"));
  ASSERT_FALSE(major);
  EXPECT_NE(major.error().message.find("'vrpn: ver. 06.01  0'"), std::string::npos) << major.error().message;
  auto http = check_cookie(cookie("HTTP/1.1 400 Bad Request"));
  ASSERT_FALSE(http);
  EXPECT_NE(http.error().message.find("HTTP/1.1 400 Bad"), std::string::npos) << http.error().message;
  EXPECT_FALSE(check_cookie(cookie("vrpn: ver. 07.38  7")));
  EXPECT_FALSE(check_cookie(cookie("vrpn: ver. 07.38")).has_value()) << "no log digit";
  EXPECT_FALSE(check_cookie(ascii("vrpn: ver. 07.38  0")).has_value()) << "short of 24 bytes";
}

// Fact (vrpn_Endpoint::marshall_message): five big-endian 32-bit words (length, seconds,
// microseconds, sender, type), a sixth holding a sequence number, the payload, and zeros
// up to a multiple of 8; the length counts the 24-byte header and the unpadded payload.
TEST(VrpnFraming, HeaderWordsAreBigEndianAndThePayloadIsPaddedTo8) {
  const Message m{3, 7, 1'700'000'000'123'456, ascii("abc")};
  const Bytes expected = hex(
      "00 00 00 1b"    // length: 24 + 3
      "65 53 f1 00"    // 1700000000 s
      "00 01 e2 40"    // 123456 us
      "00 00 00 03"    // sender id
      "00 00 00 07"    // type id
      "00 00 00 05"    // sequence number (read by no receiver)
      "61 62 63 00 00 00 00 00");  // "abc" and 5 bytes of padding
  EXPECT_EQ(framed(m, 5), expected);
}

TEST(VrpnFraming, AnEmptyPayloadIsTheHeaderAlone) {
  EXPECT_EQ(framed({1, 2, 0, {}}), hex("00 00 00 18 00000000 00000000 00000001 00000002 00000000"));
}

TEST(VrpnFraming, DecodesWhatItEncodesAndWaitsForTheWholeMessage) {
  const Message m{-1, 9, 1'234'567'890'000'001, ascii("twelve bytes")};
  const Bytes b = framed(m);
  ASSERT_EQ(b.size(), 24u + 16u);
  for (std::size_t cut = 0; cut < b.size(); ++cut) {
    auto partial = decode_message(std::span(b).first(cut));
    ASSERT_TRUE(partial) << cut;
    EXPECT_FALSE(partial->has_value()) << "a message cut at " << cut << " bytes";
  }
  auto whole = decode_message(b);
  ASSERT_TRUE(whole && *whole);
  EXPECT_EQ((*whole)->consumed, b.size());
  EXPECT_EQ((*whole)->message.sender, -1);
  EXPECT_EQ((*whole)->message.type, 9);
  EXPECT_EQ((*whole)->message.time_us, m.time_us);
  EXPECT_EQ((*whole)->message.payload, m.payload);
}

// Fact (getOneTCPMessage): the receiver's buffer holds 64000 bytes (vrpn_CONNECTION_TCP_BUFLEN).
TEST(VrpnFraming, RejectsALengthBelowTheHeaderOrBeyondVrpnsBuffer) {
  auto below = decode_message(hex("00 00 00 17 00000000 00000000 00000000 00000000 00000000"));
  ASSERT_FALSE(below);
  EXPECT_NE(below.error().message.find("length 23"), std::string::npos) << below.error().message;
  EXPECT_TRUE(decode_message(hex("00 00 fa 18 00000000 00000000 00000000 00000000 00000000")).has_value())
      << "24 + 64000 is the largest (and waits for its payload)";
  auto beyond = decode_message(hex("00 00 fa 19 00000000 00000000 00000000 00000000 00000000"));
  ASSERT_FALSE(beyond);
  EXPECT_NE(beyond.error().message.find("64000"), std::string::npos) << beyond.error().message;
}

// Fact (handle_udp_messages): a datagram holds messages back to back.
TEST(VrpnFraming, ADatagramHoldsSeveralMessagesAndMustEndWithOne) {
  Bytes datagram = concat({framed({0, 1, 5, ascii("x")}), framed({2, 3, 6, {}})});
  auto messages = decode_datagram(datagram);
  ASSERT_TRUE(messages) << messages.error().message;
  ASSERT_EQ(messages->size(), 2u);
  EXPECT_EQ((*messages)[1].sender, 2);
  datagram.pop_back();
  EXPECT_FALSE(decode_datagram(datagram));
}

// Fact (vrpn_Connection.h): system types -1 sender, -2 type, -3 UDP, -4 log description.
// Fact (pack_sender_description / pack_type_description): the sender field is the id
// described; the payload the name's length with its NUL (big-endian 32 bits), the name,
// the NUL.
TEST(VrpnSystemMessages, SenderDescriptionOfTracker0) {
  const Bytes expected = hex(
      "00 00 00 25"    // 24 + 13
      "00 00 00 00 00 00 00 00"  // time 0
      "00 00 00 04"    // the id described
      "ff ff ff ff"    // -1: sender description
      "00 00 00 00"
      "00 00 00 09"    // strlen("Tracker0") + 1
      "54 72 61 63 6b 65 72 30 00"  // "Tracker0" NUL
      "00 00 00");     // padding to 16
  EXPECT_EQ(framed({4, kSenderDescription, 0, name_description("Tracker0")}), expected);
}

TEST(VrpnSystemMessages, TypeDescriptionOfPosQuat) {
  const Bytes payload = name_description(kTrackerPosQuat);
  EXPECT_EQ(payload, concat({hex("00 00 00 16"), ascii("vrpn_Tracker Pos_Quat"), hex("00")}));  // 21 + 1
  const Bytes m = framed({1, kTypeDescription, 0, payload});
  EXPECT_EQ(Bytes(m.begin(), m.begin() + 4), hex("00 00 00 32"));  // 24 + 26
  EXPECT_EQ(Bytes(m.begin() + 16, m.begin() + 20), hex("ff ff ff fe"));
  EXPECT_EQ(m.size(), 24u + 32u);
}

// Fact (pack_udp_description, handle_UDP_message): the sender field is the UDP port, the
// payload the host's address and a NUL.
TEST(VrpnSystemMessages, UdpDescriptionCarriesThePortInTheSenderField) {
  const Bytes expected = concat({hex("00 00 00 22 00000000 00000000"), hex("00 00 13 88"),  // port 5000
                                 hex("ff ff ff fd 00000000"), ascii("127.0.0.1"), hex("00 000000000000")});
  EXPECT_EQ(framed({5000, kUdpDescription, 0, udp_description("127.0.0.1")}), expected);
  EXPECT_EQ(parse_udp_description(udp_description("10.1.2.3")).value(), "10.1.2.3");
  EXPECT_FALSE(parse_udp_description(ascii("no terminator")));
}

// Fact (handle_sender_message): a description longer than vrpn_CNAME (100 bytes) is refused.
TEST(VrpnSystemMessages, NameDescriptionsAreCheckedAgainstTheirLength) {
  EXPECT_EQ(parse_name_description(name_description("Tracker0")).value(), "Tracker0");
  EXPECT_FALSE(parse_name_description(hex("00 00 00 05 41 42 00")));      // says 5, holds 3
  EXPECT_FALSE(parse_name_description(hex("00 00 00 03 41 42 43")));      // no NUL at its end
  EXPECT_FALSE(parse_name_description(hex("00 00 00 01 00")));            // an empty name
  EXPECT_TRUE(parse_name_description(name_description(std::string(95, 'n'))));
  EXPECT_FALSE(parse_name_description(name_description(std::string(96, 'n'))));
  EXPECT_FALSE(is_valid_vrpn_name(std::string(96, 'n')));
  EXPECT_FALSE(is_valid_vrpn_name("tab\there"));
}

// Fact (vrpn_Tracker::encode_to, vrpn_Tracker_Remote::handle_change_message): the sensor
// as a 32-bit integer twice (the second for alignment), then position x y z and the
// quaternion x y z w as big-endian doubles: 64 bytes.
TEST(VrpnTrackerReport, PosQuatPayloadByteForByte) {
  const TrackerReport r{2, {1.0, -2.5, 0.125}, {0.0, 0.0, 0.6, 0.8}};
  const Bytes expected = hex(
      "00 00 00 02  00 00 00 02"
      "3f f0 00 00 00 00 00 00"  // x 1.0
      "c0 04 00 00 00 00 00 00"  // y -2.5
      "3f c0 00 00 00 00 00 00"  // z 0.125
      "00 00 00 00 00 00 00 00"  // qx 0
      "00 00 00 00 00 00 00 00"  // qy 0
      "3f e3 33 33 33 33 33 33"  // qz 0.6
      "3f e9 99 99 99 99 99 9a");  // qw 0.8
  EXPECT_EQ(encode_pos_quat(r), expected);
  auto back = decode_pos_quat(expected);
  ASSERT_TRUE(back);
  EXPECT_EQ(back->sensor, 2);
  EXPECT_EQ(back->position_m, r.position_m);
  EXPECT_EQ(back->quaternion_xyzw, r.quaternion_xyzw);
}

TEST(VrpnTrackerReport, RejectsAWrongSizeAndNumbersThatAreNoPose) {
  Bytes b = encode_pos_quat({0, {0, 0, 0}, {0, 0, 0, 1}});
  EXPECT_FALSE(decode_pos_quat(std::span(b).first(56)));
  Bytes nan = b;
  for (int i = 8; i < 16; ++i) nan[i] = 0xff;  // x = NaN
  EXPECT_FALSE(decode_pos_quat(nan));
  EXPECT_FALSE(decode_pos_quat(encode_pos_quat({0, {0, 0, 0}, {0, 0, 0, 0}})));
}

// VRPN's quaternion is x y z w, covtrack's w x y z; both give T_source_sensor in metres.
TEST(VrpnTrackerReport, ConvertsBetweenCovtrackPosesAndVrpnOrder) {
  const double half = 0.3;  // a rotation of 0.6 rad about z
  const Pose T = pose_from(Vec3(0.1, 0.2, 1.5), Eigen::Quaterniond(std::cos(half), 0, 0, std::sin(half)));
  const TrackerReport r = report_of(4, T);
  EXPECT_EQ(r.sensor, 4);
  EXPECT_DOUBLE_EQ(r.position_m[2], 1.5);
  EXPECT_NEAR(r.quaternion_xyzw[2], std::sin(half), 1e-15);
  EXPECT_NEAR(r.quaternion_xyzw[3], std::cos(half), 1e-15);
  EXPECT_NEAR(r.quaternion_xyzw[0], 0, 1e-15);
  EXPECT_TRUE(pose_of(r).isApprox(T, 1e-14));
  // A quaternion of another length is the same rotation (VRPN servers do not all normalise).
  TrackerReport scaled = r;
  for (double& q : scaled.quaternion_xyzw) q *= 3;
  EXPECT_TRUE(pose_of(scaled).isApprox(T, 1e-14));
}

// Fact (finish_new_connection_setup): after the peer's cookie each side describes its
// senders, then its types, ids counting from 0; messages carry the sender's ids.
TEST(VrpnSession, HandshakeThenDescriptionsThenMessagesByName) {
  Session s({"Tracker0"}, {std::string(kTrackerPosQuat), std::string(kPing)});
  const Cookie ours = make_cookie();
  EXPECT_EQ(s.take_output(), Bytes(ours.begin(), ours.end())) << "the cookie alone, before the peer's";
  EXPECT_FALSE(s.send("Tracker0", kPing, 0, {})) << "VRPN discards messages before the handshake";

  // The peer: an older minor version, its own ids (sender 7, type 12).
  Bytes peer = ascii("vrpn: ver. 07.35  0");
  peer.resize(kCookieSize, 0);
  const Bytes peer_names = concat({framed({7, kSenderDescription, 0, name_description("Tracker0")}),
                                   framed({12, kTypeDescription, 0, name_description(kTrackerPosQuat)}),
                                   framed({3000, kUdpDescription, 0, udp_description("127.0.0.1")})});
  const Bytes report = framed({7, 12, 1'000'000'000'000'042, encode_pos_quat({1, {1, 2, 3}, {0, 0, 0, 1}})});
  const Bytes undescribed = framed({7, 13, 0, {}});
  const Bytes all = concat({peer, peer_names, report, undescribed});

  // Fed one byte at a time: TCP may split anywhere.
  std::vector<NamedMessage> got;
  for (std::uint8_t byte : all) {
    auto r = s.receive(std::span(&byte, 1), 99);
    ASSERT_TRUE(r) << r.error().message;
    got.insert(got.end(), r->begin(), r->end());
  }
  ASSERT_TRUE(s.ready());
  EXPECT_TRUE(s.peer()->minor_differs);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].sender, "Tracker0");
  EXPECT_EQ(got[0].type, kTrackerPosQuat);
  EXPECT_EQ(got[0].time_us, 1'000'000'000'000'042);
  EXPECT_EQ(s.undescribed(), 1u);
  ASSERT_TRUE(s.peer_udp());
  EXPECT_EQ(s.peer_udp()->port, 3000);

  const Bytes descriptions = concat({framed({0, kSenderDescription, 99, name_description("Tracker0")}, 0),
                                     framed({0, kTypeDescription, 99, name_description(kTrackerPosQuat)}, 1),
                                     framed({1, kTypeDescription, 99, name_description(kPing)}, 2)});
  EXPECT_EQ(s.take_output(), descriptions);
  ASSERT_TRUE(s.send("Tracker0", kPing, 5, {}));
  EXPECT_EQ(s.take_output(), framed({0, 1, 5, {}}, 3));
  EXPECT_FALSE(s.send("Tracker1", kPing, 5, {})) << "not a sender of ours";
}

TEST(VrpnSession, ABadCookieOrHeaderEndsTheConnectionWithAReason) {
  Session s({"T"}, {"t"});
  auto bad = s.receive(ascii("SSH-2.0-OpenSSH_9.2p1 Debian-2\r\n"), 0);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("'SSH-2.0-OpenSSH_9.2p1 De'"), std::string::npos) << bad.error().message;

  Session t({"T"}, {"t"});
  const Cookie c = make_cookie();
  const Bytes cookie(c.begin(), c.end());
  ASSERT_TRUE(t.receive(cookie, 0));
  EXPECT_FALSE(t.receive(hex("00 00 00 04 00000000 00000000 00000000 00000000 00000000"), 0));
  Session u({"T"}, {"t"});
  ASSERT_TRUE(u.receive(cookie, 0));
  EXPECT_FALSE(u.receive(framed({2000, kSenderDescription, 0, name_description("x")}), 0))
      << "VRPN's ids are below 2000";
}

TEST(VrpnTrackerAddress, ParsesVrpnNames) {
  auto plain = parse_tracker_address("Tracker0@localhost");
  ASSERT_TRUE(plain);
  EXPECT_EQ(plain->name, "Tracker0");
  EXPECT_EQ(plain->host, "localhost");
  EXPECT_EQ(plain->port, kDefaultPort);
  EXPECT_EQ(plain->text(), "Tracker0@localhost:3883");
  auto tcp = parse_tracker_address("DTrack@tcp://10.0.0.5:3884");
  ASSERT_TRUE(tcp);
  EXPECT_EQ(tcp->endpoint(), "10.0.0.5:3884");
  for (const char* bad : {"Tracker0", "@host", "Tracker0@", "Tracker0@host:0", "Tracker0@host:x", "Tracker0@ho st",
                          "Tracker0@host:70000"}) {
    auto r = parse_tracker_address(bad);
    ASSERT_FALSE(r) << bad;
    EXPECT_NE(r.error().message.find(bad), std::string::npos) << r.error().message;
  }
}

// Fact (finish_new_connection_setup, pack_udp_description): a client not connected over
// TCP only tells the server its UDP port in the sender field of a type -3 message whose
// payload is its address and a NUL; like any message, not before the handshake.
TEST(VrpnSession, UdpDescriptionAfterTheHandshakeByteForByte) {
  Session s({"Tracker0"}, {std::string(kTrackerPosQuat)});
  s.take_output();
  EXPECT_FALSE(s.describe_udp("127.0.0.1", 40000, 0)) << "nothing but the cookie before the peer's cookie";
  const Cookie c = make_cookie();
  ASSERT_TRUE(s.receive(Bytes(c.begin(), c.end()), 0));
  s.take_output();  // our descriptions
  ASSERT_TRUE(s.describe_udp("127.0.0.1", 40000, 2'000'003));
  EXPECT_EQ(s.take_output(), hex("00 00 00 22  00 00 00 02  00 00 00 03  00 00 9c 40  ff ff ff fd  00 00 00 02"
                                 "31 32 37 2e 30 2e 30 2e 31 00  00 00 00 00 00 00"));
}
