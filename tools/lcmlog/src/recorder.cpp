#include "covtrack/lcmlog/recorder.hpp"

#include <poll.h>

#include <cerrno>
#include <chrono>
#include <cstring>

#include "covtrack/lcmlog/channel_filter.hpp"
#include "covtrack/lcmlog/log_reader.hpp"
#include "covtrack/protocol/channel_messages.hpp"

namespace covtrack::lcmlog {
namespace {
constexpr std::string_view kLcmSelfTestChannel = "LCM_SELF_TEST";
}  // namespace

Result<std::unique_ptr<Recorder>> Recorder::start(lcm::LCM& lcm, LogWriter& writer,
                                                  const std::string& channel_regex) {
  // LCM would report a bad regex only as a null subscription; check it first to say why.
  if (auto filter = ChannelFilter::create(channel_regex); !filter)
    return std::unexpected(filter.error());
  std::unique_ptr<Recorder> recorder(new Recorder(lcm, writer));
  recorder->subscription_ = lcm.subscribe(channel_regex, &Recorder::on_message, recorder.get());
  if (!recorder->subscription_)
    return fail("LCM refused to subscribe to channels '" + channel_regex + "'");
  recorder->subscription_->setQueueCapacity(kRecordQueueCapacity);
  return recorder;
}

Recorder::~Recorder() {
  if (subscription_) lcm_.unsubscribe(subscription_);
}

void Recorder::on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  // Every udpm instance that subscribes multicasts this probe to check its own loopback;
  // it is LCM's plumbing, not part of the session.
  if (write_error_ || channel == kLcmSelfTestChannel) return;
  const std::span payload(static_cast<const std::byte*>(rbuf->data), rbuf->data_size);
  if (auto ok = writer_.write(stamps_.stamp(rbuf->recv_utime), channel, payload); !ok) {
    write_error_ = ok.error();
    return;
  }
  ++summary_.events;
  summary_.bytes += kEventHeaderBytes + channel.size() + rbuf->data_size;
  ++summary_.events_per_channel[channel];
  if (const auto bad = check_channel_message(channel, payload))
    summary_.bad_messages.add(to_string(bad->fault), channel, bad->describe());
}

Result<RecordSummary> Recorder::run(int stop_fd, std::optional<double> duration_s) {
  using Clock = std::chrono::steady_clock;
  const auto started = Clock::now();
  const auto deadline =
      duration_s ? started + std::chrono::duration_cast<Clock::duration>(
                                 std::chrono::duration<double>(*duration_s))
                 : Clock::time_point::max();
  pollfd fds[2] = {{lcm_.getFileno(), POLLIN, 0}, {stop_fd, POLLIN, 0}};
  while (!write_error_) {
    int timeout_ms = -1;
    if (duration_s) {
      const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now());
      if (left.count() <= 0) break;
      timeout_ms = static_cast<int>(std::min<long long>(left.count(), 1 << 30));
    }
    const int ready = ::poll(fds, stop_fd >= 0 ? 2 : 1, timeout_ms);
    if (ready < 0 && errno == EINTR) continue;  // the signal's byte is in the pipe
    if (ready < 0) return fail(std::string("poll failed while recording: ") + std::strerror(errno));
    if (stop_fd >= 0 && (fds[1].revents & (POLLIN | POLLHUP))) break;
    if (fds[0].revents & POLLIN) lcm_.handle();  // readable: a message is waiting
  }
  // Messages LCM received before the stop are already queued: keep them.
  while (!write_error_ && lcm_.handleTimeout(0) > 0) {
  }
  if (write_error_) return std::unexpected(*write_error_);
  summary_.duration_s = std::chrono::duration<double>(Clock::now() - started).count();
  summary_.restamped = stamps_.restamped();
  return summary_;
}

}  // namespace covtrack::lcmlog
