#include "driver_factory.hpp"

namespace covtrack::server {
namespace {
// One per alternative of DriverOptions: a missing one does not compile.
std::unique_ptr<Driver> make_one(const sim::SimConfig& c, std::uint64_t run) { return sim::make_sim_driver(c, run); }
std::unique_ptr<Driver> make_one(const lenz::LenzConfig& c, std::uint64_t) { return lenz::make_lenz_driver(c); }
std::unique_ptr<Driver> make_one(const serial6dof::Serial6dofConfig& c, std::uint64_t run) {
  return serial6dof::make_serial6dof_driver(c, run);
}
std::unique_ptr<Driver> make_one(const hydra::HydraConfig& c, std::uint64_t) { return hydra::make_hydra_driver(c); }
std::unique_ptr<Driver> make_one(const std::shared_ptr<const fiducial::FiducialConfig>& c, std::uint64_t run) {
  return fiducial::make_fiducial_driver(*c, run);
}
std::unique_ptr<Driver> make_one(const vrpn::VrpnConfig& c, std::uint64_t) { return vrpn::make_vrpn_driver(c); }
std::unique_ptr<Driver> make_one(const DriverFactory& make, std::uint64_t run) { return make(run); }
}  // namespace

std::unique_ptr<Driver> make_driver(const DriverOptions& options, std::uint64_t run_index) {
  return std::visit([run_index](const auto& c) { return make_one(c, run_index); }, options);
}

}  // namespace covtrack::server
