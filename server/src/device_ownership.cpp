#include "device_ownership.hpp"

#include <poll.h>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "covtrack/protocol/channel_messages.hpp"
#include "covtrack/protocol/channels.hpp"
#include "covtrack/protocol/clock.hpp"

namespace covtrack::server {
namespace {
// Claims sent over the wait: a lost datagram, or a daemon that starts listening in the
// middle of another's wait, still meets one of them.
constexpr int kClaimsPerWait = 4;
// How long the listening thread sleeps in poll() before it looks at its stop token.
constexpr int kPollMs = 50;

std::string any_of(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : "|") + n;  // names are [A-Za-z0-9_-]
  return "(" + out + ")";
}
}  // namespace

std::string describe_daemon(const std::string& host, std::int32_t pid, std::int64_t instance_id) {
  return fmt::format("{}/{} (instance {:016x})", host, pid, static_cast<std::uint64_t>(instance_id));
}

Result<std::unique_ptr<DeviceOwnership>> DeviceOwnership::open(lcm::LCM& lcm, const std::string& url,
                                                               PublisherIdentity identity,
                                                               const std::vector<std::string>& devices,
                                                               ClaimSettings settings, GiveUp give_up) {
  std::unique_ptr<DeviceOwnership> o(
      new DeviceOwnership(lcm, std::move(identity), devices, settings, std::move(give_up)));
  if (url.starts_with("udpm://")) {
    auto listener = ClaimListener::open(url);
    if (!listener) return std::unexpected(listener.error());
    o->listener_ = std::move(*listener);
  } else {
    for (const auto prefix : {kClaimPrefix, kStatusPrefix})
      o->subscriptions_.push_back(
          lcm.subscribe(std::string(prefix) + any_of(devices), &DeviceOwnership::on_lcm_message, o.get()));
  }
  o->thread_ = std::jthread([raw = o.get()](std::stop_token stop) { raw->listen(stop); });
  return o;
}

DeviceOwnership::DeviceOwnership(lcm::LCM& lcm, PublisherIdentity identity, const std::vector<std::string>& devices,
                                 ClaimSettings settings, GiveUp give_up)
    : lcm_(lcm), identity_(std::move(identity)), settings_(settings), give_up_(std::move(give_up)),
      claimed_us_(now_us()) {
  for (const auto& d : devices) devices_[d];
}

DeviceOwnership::~DeviceOwnership() {
  if (thread_.joinable()) {
    thread_.request_stop();
    thread_.join();
  }
  for (auto* s : subscriptions_) lcm_.unsubscribe(s);
}

void DeviceOwnership::listen(std::stop_token stop) {
  if (listener_) {
    while (!stop.stop_requested())
      if (auto m = listener_->receive(kPollMs)) on_message(m->channel, m->bytes);
    return;
  }
  pollfd pfd{lcm_.getFileno(), POLLIN, 0};
  while (!stop.stop_requested())
    if (::poll(&pfd, 1, kPollMs) > 0) lcm_.handle();
}

void DeviceOwnership::on_lcm_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  on_message(channel, bytes_of(rbuf->data, rbuf->data_size));
}

// Only our devices' channels count; the listener lets every device's through.
void DeviceOwnership::on_message(const std::string& channel, std::span<const std::byte> bytes) {
  if (channel.starts_with(kClaimPrefix)) {
    if (!devices_.contains(channel.substr(kClaimPrefix.size()))) return;
    const auto claim = decode_claim(channel, bytes);
    if (claim) on_claim(*claim);
    else spdlog::debug("covtrackd: ignored a claim on {}: {}", channel, claim.error().describe());
  } else if (channel.starts_with(kStatusPrefix)) {
    if (!devices_.contains(channel.substr(kStatusPrefix.size()))) return;
    if (const auto status = decode_status(channel, bytes)) on_status(*status);
  }
}

std::optional<std::map<std::string, std::string>> DeviceOwnership::claim(const Wait& wait) {
  const auto slice = std::chrono::milliseconds(static_cast<long>(settings_.wait_s * 1000 / kClaimsPerWait));
  for (int i = 0; settings_.wait_s > 0 && i < kClaimsPerWait; ++i) {
    {
      std::lock_guard lock(mutex_);
      for (const auto& [name, device] : devices_) send_claim(name, device_claim_t::STAGE_CLAIMING);
    }
    if (!wait(slice)) return std::nullopt;
  }
  std::map<std::string, std::string> refused;
  std::lock_guard lock(mutex_);
  for (auto& [name, device] : devices_) {
    const auto why = held_elsewhere(device);
    if (why && !settings_.allow_duplicates) {
      device.stage = Stage::Refused;
      refused[name] = *why + "; stop that daemon first, or set daemon.allow_duplicate_publishers "
                             "(--allow-duplicate-publishers) to publish the device twice";
      continue;
    }
    device.stage = Stage::Holding;
    for (auto& [id, other] : device.others) name_once(name, id, other);
  }
  return refused;
}

bool DeviceOwnership::comes_first(std::int64_t instance_id, const Other& other) const {
  if (other.claimed_us == 0) return false;  // no claim of it heard: nothing to compare
  if (other.claimed_us != claimed_us_) return other.claimed_us < claimed_us_;
  return instance_id < identity_.instance_id;
}

std::optional<std::string> DeviceOwnership::held_elsewhere(const Device& device) const {
  for (const auto& [id, other] : device.others)
    if (other.holding) return "covtrackd on " + describe_daemon(other.host, other.pid, id) + " already publishes it";
  for (const auto& [id, other] : device.others)
    if (comes_first(id, other))
      return "covtrackd on " + describe_daemon(other.host, other.pid, id) +
             " claimed it at the same time and comes first (the earlier claim, then the smaller instance id)";
  return std::nullopt;
}

void DeviceOwnership::name_once(const std::string& device, std::int64_t instance_id, Other& other) {
  if (other.named || !other.holding) return;
  other.named = true;
  spdlog::warn("covtrackd: device '{}' is also published by covtrackd on {}{}", device,
               describe_daemon(other.host, other.pid, instance_id),
               settings_.allow_duplicates ? "; publishing it anyway (daemon.allow_duplicate_publishers)"
                                          : "; of the two, the later claim gives it up unless it allows duplicates");
}

void DeviceOwnership::send_claim(const std::string& device, std::int8_t stage) {
  device_claim_t claim;
  claim.time_us = now_us();
  claim.device = device;
  claim.instance_id = identity_.instance_id;
  claim.host = identity_.host;
  claim.pid = identity_.pid;
  claim.claimed_us = claimed_us_;
  claim.stage = stage;
  lcm_.publish(claim_channel(device), &claim);
}

void DeviceOwnership::on_claim(const device_claim_t& claim) {
  if (claim.instance_id == identity_.instance_id) return;  // our own, looped back
  std::optional<std::string> given_up;
  {
    std::lock_guard lock(mutex_);
    Device& device = devices_[claim.device];
    Other& other = device.others[claim.instance_id];
    other.claimed_us = claim.claimed_us;
    other.host = claim.host;
    other.pid = claim.pid;
    other.holding = other.holding || claim.stage == device_claim_t::STAGE_HOLDING;
    if (device.stage != Stage::Holding) return;  // a claimant decides at the end of its wait
    if (claim.stage == device_claim_t::STAGE_CLAIMING) {
      send_claim(claim.device, device_claim_t::STAGE_HOLDING);  // the answer: we hold it
      return;
    }
    // Given up only to a daemon whose heartbeats were heard too: a claim alone (one
    // datagram anyone can send) does not stop a device.
    if (!comes_first(claim.instance_id, other) || !other.publishing || settings_.allow_duplicates) {
      name_once(claim.device, claim.instance_id, other);
      return;
    }
    device.stage = Stage::Refused;
    given_up = "covtrackd on " + describe_daemon(other.host, other.pid, claim.instance_id) +
               " publishes it too and claimed it first (" +
               fmt::format("{:.3f} s before this daemon", 1e-6 * static_cast<double>(claimed_us_ - other.claimed_us)) +
               "); this daemon gives it up";
  }
  give_up_(claim.device, *given_up);
}

void DeviceOwnership::on_status(const device_status_t& status) {
  if (status.instance_id == identity_.instance_id) return;  // our own, looped back
  std::lock_guard lock(mutex_);
  Device& device = devices_[status.device];
  Other& other = device.others[status.instance_id];
  other.holding = true;
  other.publishing = true;
  other.host = status.host;
  other.pid = status.pid;
  // Two holders: ours goes out so that the later of the two learns it and gives up.
  if (device.stage != Stage::Holding) return;
  name_once(status.device, status.instance_id, other);
  send_claim(status.device, device_claim_t::STAGE_HOLDING);
}

}  // namespace covtrack::server
