#include "covtrack/protocol/lcm_reassembly.hpp"

#include <algorithm>
#include <cstring>

#include <fmt/format.h>

#include "rejection.hpp"

namespace covtrack::lcm_wire {

Reassembler::Reassembler(ReassemblyLimits limits) : limits_(limits) {
  limits_.max_total_bytes = std::max<std::size_t>(limits_.max_total_bytes, limits_.max_message_bytes);
  limits_.max_partial_messages = std::max<std::size_t>(limits_.max_partial_messages, 1);
}

Reassembler::Partial* Reassembler::find(const Sender& from) {
  for (auto& p : partials_)
    if (p.from == from) return &p;
  return nullptr;
}

void Reassembler::drop(Partial* p, bool count_as_abandoned) {
  abandoned_ += count_as_abandoned && !p->ignored;
  bytes_held_ -= p->payload.size();
  if (p != &partials_.back()) *p = std::move(partials_.back());
  partials_.pop_back();
}

void Reassembler::expire(std::int64_t now_us) {
  for (std::size_t i = partials_.size(); i-- > 0;)
    if (partials_[i].last_us < now_us - limits_.stale_after_us) drop(&partials_[i], true);
}

Reassembler::Partial& Reassembler::start(const Sender& from, const Fragment& f, std::int64_t now_us, bool ignored) {
  const std::size_t size = ignored ? 0 : f.message_size;
  // Room first: the partial message heard from longest ago goes.
  while (!partials_.empty() && (partials_.size() >= limits_.max_partial_messages ||
                                bytes_held_ + size > limits_.max_total_bytes))
    drop(&*std::min_element(partials_.begin(), partials_.end(),
                            [](const Partial& a, const Partial& b) { return a.last_us < b.last_us; }),
         true);
  Partial& p = partials_.emplace_back();
  p.from = from;
  p.sequence = f.sequence;
  p.ignored = ignored;
  p.count = f.count;
  p.last_us = now_us;
  if (!ignored) {
    p.have.assign(f.count, false);
    p.channel = f.channel;
    p.payload.resize(size);
    bytes_held_ += size;
  }
  return p;
}

std::expected<std::optional<CompleteMessage>, DatagramRejection> Reassembler::add(const Sender& from,
                                                                                  const Fragment& f,
                                                                                  std::int64_t now_us,
                                                                                  const Wanted& wanted) {
  expire(now_us);
  Partial* p = find(from);
  if (p && p->sequence != f.sequence) {  // the sender has moved on: the rest will not come
    drop(p, true);
    p = nullptr;
  }
  if (!p) {
    if (f.number != 0) return std::nullopt;  // its fragment 0 was lost: nothing to add to
    if (f.message_size > limits_.max_message_bytes) {
      start(from, f, now_us, true);
      return reject(DatagramFault::TooLarge, fmt::format("a message of {} bytes on '{}' (at most {})", f.message_size,
                                                         f.channel, limits_.max_message_bytes));
    }
    const bool keep = !wanted || wanted(f.channel);
    p = &start(from, f, now_us, !keep);
    if (!keep) return std::nullopt;
  } else if (p->ignored) {
    p->last_us = now_us;
    return std::nullopt;
  } else if (f.count != p->count || f.message_size != p->payload.size()) {
    const auto detail = fmt::format("fragment {} says {} fragments and {} bytes, fragment 0 said {} and {}",
                                    f.number, f.count, f.message_size, p->count, p->payload.size());
    drop(p, true);
    return reject(DatagramFault::Inconsistent, detail);
  } else if (p->have[f.number]) {
    return reject(DatagramFault::Duplicate, fmt::format("fragment {} of {} again", f.number, f.count));
  }
  if (!f.data.empty()) std::memcpy(p->payload.data() + f.offset, f.data.data(), f.data.size());
  p->have[f.number] = true;
  ++p->received;
  p->bytes_received += f.data.size();
  p->last_us = now_us;
  if (p->received < p->count) return std::nullopt;
  if (p->bytes_received != p->payload.size()) {
    const auto detail = fmt::format("{} fragments carry {} bytes for a message of {}", p->count,
                                    p->bytes_received, p->payload.size());
    drop(p, true);
    return reject(DatagramFault::Inconsistent, detail);
  }
  CompleteMessage done{std::move(p->channel), std::move(p->payload)};
  p->payload.clear();
  bytes_held_ -= done.payload.size();
  drop(p, false);
  return done;
}

}  // namespace covtrack::lcm_wire
