// A simulated walk (terrain::simulate_walk) as the sample stream a phone would log: Meta lines
// (declared start, user height, DEM), rotation vector (chest mount, magnetic heading) before
// each Android step event, pressure, and Truth lines. Used by eval-terrain's app path, which
// writes it through io::LogWriter, reads it back with io::LogReader and replays it through
// fusion::Navigator exactly as `pdnav replay` does, and by `pdnav simulate` to write the log.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "pdnav/geo/samples.h"
#include "pdnav/terrain/dem.h"
#include "pdnav/terrain/simulator.h"

namespace pdnav::cli {

/// Wall-clock time of a simulated session's first sample (2026-06-01T08:00Z): sets the utc_ms
/// of every sample, so the replay's WMM declination is that of a real session.
inline constexpr std::int64_t kSimSessionStartUnixMs = 1780300800000;

/// Rotation vector (phone -> ENU, magnetic north) of a chest-mounted phone, top edge up, camera
/// facing the walking direction (pdr::Mount::kChestCameraOut, the app's mount).
RotationVectorSample chest_rotation_for_heading(TimeNs t_ns, std::int64_t utc_ms, double magnetic_heading_rad,
                                                double accuracy_rad);

/// Time-ordered samples of the walk (Meta lines first). dem_name goes into Meta DemFile,
/// "<simulator> seed <seed>" into Meta Simulator (which command made the walk).
std::vector<Sample> walk_to_samples(const terrain::SimulatedWalk& w, const terrain::Dem& dem, double user_height_m,
                                    const std::string& dem_name, std::uint64_t seed,
                                    const std::string& simulator = "pdnav eval-terrain walk");

}  // namespace pdnav::cli
