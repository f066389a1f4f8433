// LIBERTY / PATRIOT configuration (PDI SDK, VRPN): ^Y reset, P (stop continuous),
// F1 (binary), ^V (who-am-I), U0/U1 (units), U (query, confirms the units),
// O<st>,2,7,...,1 (output list), C (continuous).
#include <fmt/format.h>

#include "device_session.hpp"
#include "float_le.hpp"
#include "liberty_decoder.hpp"

namespace covtrack::serial6dof {
namespace {

class LibertySession final : public DecodingSession<LibertyDecoder> {
 public:
  explicit LibertySession(const Serial6dofConfig& c)
      : DecodingSession(c, LibertyFormat{c.units, c.liberty_extras}) {}

  Result<void> start(DeviceLink& link, bool reset) override {
    using namespace std::chrono_literals;
    if (reset) {
      if (auto r = link.send("\x19\r"); !r) return r;
      if (!link.sleep(config_.reset_time_s)) return {};
    }
    if (auto r = link.send("P"); !r) return r;
    if (auto r = link.drain(100ms); !r) return r;
    if (auto r = link.send("F1\r"); !r) return r;
    if (auto r = link.send("\x16\r"); !r) return r;
    auto who = await(link, 0x16);
    if (!who) return std::unexpected(who.error());
    if (!*who) return no_reply(link, "who-am-I (^V)");
    who_am_i_ = (*who)->payload;

    if (auto r = link.send(config_.units == Units::Inches ? "U0\r" : "U1\r"); !r) return r;
    if (auto r = link.send("U\r"); !r) return r;
    auto units = await(link, 'U');
    if (!units) return std::unexpected(units.error());
    if (!*units) return no_reply(link, "the units query (U)");
    const std::string& p = (*units)->payload;
    if (p.size() < 4) return fail(fmt::format("{}: malformed units reply", link.path()));
    const auto code = read_u32_le(reinterpret_cast<const std::uint8_t*>(p.data()));
    const std::uint32_t wanted = config_.units == Units::Inches ? 0 : 1;
    if (code != wanted)
      return fail(fmt::format("{}: units not confirmed: the unit reports U{}, U{} was set",
                              link.path(), code, wanted));
    for (const auto& st : config_.stations)
      if (auto r = link.send(liberty_output_list_command(st.number, {config_.units, config_.liberty_extras})); !r)
        return r;
    return link.send("C\r");
  }

 private:
  Result<std::optional<DeviceReply>> await(DeviceLink& link, char command) {
    return await_reply(link, *this, config_.reply_timeout_s,
                       [command](const DeviceReply& r) { return r.command == command; });
  }
  Result<void> no_reply(DeviceLink& link, const char* what) {
    if (link.stopped()) return {};
    return no_answer(link, fmt::format("no answer to {} within {} s", what, config_.reply_timeout_s),
                     "the unit is on");
  }

  std::string who_am_i_;
};

}  // namespace

std::unique_ptr<DeviceSession> make_liberty_session(const Serial6dofConfig& c) {
  return std::make_unique<LibertySession>(c);
}

}  // namespace covtrack::serial6dof
