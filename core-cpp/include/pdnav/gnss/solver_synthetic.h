// Synthetic skies with known answers for the solver tests and the benchmark: satellites at
// GPS orbit radius spread in azimuth/elevation above a receiver, and exact observables
// (pseudorange with Sagnac, ADR, pseudorange rate) generated from the same geometry model.
#pragma once
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/frames.h"
#include "pdnav/gnss/ephemeris.h"
#include "pdnav/gnss/types.h"

namespace pdnav::gnss {

struct SyntheticSat {
  SatId sat;
  SatState state;  // at the epoch's transmit time (position in the transmit-time ECEF frame)
};

/// `n` satellites between 15 and 85 deg elevation, azimuths spread by the golden angle with
/// a seeded jitter (std::mt19937_64), orbit radius 26 560 km, speed 3.87 km/s. Systems are
/// assigned round-robin from `systems` (PRN = index + 1).
std::vector<SyntheticSat> synthetic_sky(const geo::Ecef& rx, int n, std::uint64_t seed,
                                        const std::vector<Constellation>& systems = {Constellation::kGps});

/// The same satellites dt_s later (straight-line motion, clock drifting at clock_drift_sps).
std::vector<SyntheticSat> propagate_sky(const std::vector<SyntheticSat>& sky, double dt_s);

/// Geometric range including the Earth rotation during the signal travel (fixed point).
double sagnac_range_m(const Eigen::Vector3d& sat_transmit_ecef, const Eigen::Vector3d& rx_ecef);

/// Range rate seen by a receiver moving at rx_vel: (v_sat - v_rx) . los, satellite position
/// and velocity rotated into the receive-time frame (Sagnac).
double range_rate_mps(const SatState& st, const Eigen::Vector3d& rx_ecef, const Eigen::Vector3d& rx_vel);

}  // namespace pdnav::gnss
