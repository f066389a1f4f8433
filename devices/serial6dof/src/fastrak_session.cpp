// FASTRAK / IS-900 configuration (FASTRAK manual): ^Y reset, c (stop), u/U (units),
// O<st>,2,11,...,1 (output list), S (status record, confirms the units), f (binary),
// C (continuous).
#include <fmt/format.h>

#include "device_session.hpp"
#include "fastrak_decoder.hpp"

namespace covtrack::serial6dof {
namespace {

const char* units_name(Units u) { return u == Units::Inches ? "inches" : "cm"; }

class FastrakSession final : public DecodingSession<FastrakDecoder> {
 public:
  explicit FastrakSession(const Serial6dofConfig& c)
      : DecodingSession(c, FastrakFormat{c.units, c.fastrak_extras, true}) {}

  Result<void> start(DeviceLink& link, bool reset) override {
    using namespace std::chrono_literals;
    if (reset) {
      if (auto r = link.send("\x19"); !r) return r;
      if (!link.sleep(config_.reset_time_s)) return {};
    }
    if (auto r = link.send("c"); !r) return r;
    if (auto r = link.drain(100ms); !r) return r;
    if (auto r = link.send(config_.units == Units::Inches ? "U" : "u"); !r) return r;
    for (const auto& st : config_.stations)
      if (auto r = link.send(fastrak_output_list_command(st.number, {config_.units, config_.fastrak_extras, true})); !r)
        return r;
    if (auto r = link.send("S"); !r) return r;
    auto reply = await_reply(link, *this, config_.reply_timeout_s,
                             [](const DeviceReply& r) { return r.command == 'S'; });
    if (!reply) return std::unexpected(reply.error());
    if (link.stopped()) return {};
    if (!*reply)
      return no_answer(link, fmt::format("no status record within {} s of 'S'", config_.reply_timeout_s),
                       "the unit is on");
    const auto units = fastrak_status_units(**reply);
    if (!units) return fail(fmt::format("{}: malformed status record", link.path()));
    if (*units != config_.units)
      return fail(fmt::format("{}: units not confirmed: the status record says {}, {} was set",
                              link.path(), units_name(*units), units_name(config_.units)));
    if (auto r = link.send("f"); !r) return r;
    return link.send("C");
  }
};

}  // namespace

std::unique_ptr<DeviceSession> make_fastrak_session(const Serial6dofConfig& c) {
  return std::make_unique<FastrakSession>(c);
}

}  // namespace covtrack::serial6dof
