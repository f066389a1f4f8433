#pragma once
// The command side of one emulated unit: its settings, what it answers, and how its
// records look in the current settings. The emulator core owns timing, noise and the
// pseudo-terminal.
#include <memory>
#include <vector>

#include "covtrack/emulators/serial6dof/emulator.hpp"
#include "record_encoder.hpp"

namespace covtrack::emulate6dof {

using serial6dof::Bytes;
using serial6dof::TrackerRecord;

class EmulatedUnit {
 public:
  virtual ~EmulatedUnit() = default;
  // Settings after power-up or reset.
  virtual void power_on() = 0;
  // Consumes every complete command at the front of `input`, appending replies to
  // `reply`; returns true when a command asked for a reset.
  virtual bool handle(std::vector<std::uint8_t>& input, Bytes& reply) = 0;
  virtual bool streaming() const = 0;
  // Records for one report of every station, in the current settings. A station's
  // status code is set by the core (trouble or not).
  virtual Bytes encode(const std::vector<TrackerRecord>& records) const = 0;
  // The status code the unit uses to flag a record; -1: its records carry none.
  virtual int trouble_code() const = 0;
};

// Appends `bytes` to `out`.
inline void append(Bytes& out, const Bytes& bytes) { out.insert(out.end(), bytes.begin(), bytes.end()); }

std::unique_ptr<EmulatedUnit> make_fastrak_unit(const EmulatorConfig& config);
std::unique_ptr<EmulatedUnit> make_liberty_unit(const EmulatorConfig& config);
std::unique_ptr<EmulatedUnit> make_flock_unit(const EmulatorConfig& config);

}  // namespace covtrack::emulate6dof
