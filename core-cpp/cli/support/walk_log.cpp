#include "support/walk_log.h"

#include <iomanip>
#include <sstream>

#include <Eigen/Geometry>

#include "pdnav/geo/wmm.h"
#include "pdnav/sim/world.h"

namespace pdnav::cli {
namespace {

std::string num(double v, int digits = 9) {
  std::ostringstream os;
  os << std::setprecision(digits) << v;
  return os.str();
}

MetaSample meta(const std::string& key, const std::string& value) { return {0, key, value}; }

}  // namespace

RotationVectorSample chest_rotation_for_heading(TimeNs t_ns, std::int64_t utc_ms, double magnetic_heading_rad,
                                                double accuracy_rad) {
  RotationVectorSample out;
  out.t_ns = t_ns;
  out.utc_ms = utc_ms;
  out.quat_xyzw = sim::chest_mount_quat_xyzw(magnetic_heading_rad);
  out.heading_accuracy_rad = accuracy_rad;
  return out;
}

std::vector<Sample> walk_to_samples(const terrain::SimulatedWalk& w, const terrain::Dem& dem, double user_height_m,
                                    const std::string& dem_name, std::uint64_t seed,
                                    const std::string& simulator) {
  std::vector<Sample> out;
  out.reserve(3 * w.steps.size() + w.pressure.size() + 8);
  out.emplace_back(meta("StartLatitudeDegrees", num(w.declared_start.lat_deg(), 12)));
  out.emplace_back(meta("StartLongitudeDegrees", num(w.declared_start.lon_deg(), 12)));
  out.emplace_back(meta("StartSigmaMeters", num(w.declared_sigma_m)));
  out.emplace_back(meta("UserHeightMeters", num(user_height_m)));
  out.emplace_back(meta("DemFile", dem_name));
  out.emplace_back(meta("DemSourceSha256", dem.info().source_sha256));
  out.emplace_back(meta("HeadingReference", "magnetic (rotation vector, chest mount, camera forward)"));
  out.emplace_back(meta("Simulator", simulator + " seed " + std::to_string(seed)));
  const auto utc_of = [&](TimeNs t_ns) { return kSimSessionStartUnixMs + (t_ns - w.t0_ns) / kNsPerMs; };
  // The phone reports magnetic heading: subtract the WMM declination the replay adds back.
  const double declination_rad = geo::magnetic_declination_rad(w.declared_start, kSimSessionStartUnixMs);
  auto pressure = [&](std::size_t i) {
    PressureSample p = w.pressure[i];
    p.utc_ms = utc_of(p.t_ns);
    return p;
  };
  std::size_t ip = 0;
  for (std::size_t k = 0; k < w.steps.size(); ++k) {
    const PdrStep& s = w.steps[k];
    while (ip < w.pressure.size() && w.pressure[ip].t_ns <= s.t_ns) out.emplace_back(pressure(ip++));
    const TimeNs t_rv = s.t_ns - kNsPerMs;  // the heading sensor reports just before the step event
    out.emplace_back(
        chest_rotation_for_heading(t_rv, utc_of(t_rv), s.heading_rad - declination_rad, s.heading_sigma_rad));
    StepDetectorSample sd;
    sd.t_ns = s.t_ns;
    sd.utc_ms = utc_of(s.t_ns);
    out.emplace_back(sd);
    out.emplace_back(w.truth[k]);
  }
  while (ip < w.pressure.size()) out.emplace_back(pressure(ip++));
  return out;
}

}  // namespace pdnav::cli
