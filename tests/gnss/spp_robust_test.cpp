// Issue 15 robust SPP: subset FDE (leave-one-out / leave-two-out on the worst standardised
// residuals) against the classic largest-residual exclusion on a synthetic sky where two
// satellites carry 30-60 m of multipath, and the IGG-III reweighting after the FDE.
#include <algorithm>
#include <cstdio>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/gnss/measurements.h"
#include "pdnav/gnss/solver_synthetic.h"
#include "pdnav/gnss/spp.h"
#include "synthetic_sky.h"

namespace pdnav::gnss {
namespace {

const geo::Ecef kRx = geo::to_ecef(geo::Geodetic::from_deg(37.4, -122.1, 10.0));

SppOptions fde_only(SppFde method) {
  SppOptions o = test::no_atmosphere();
  o.robust_igg3 = false;  // the FDE alone
  o.fde = method;
  // weights that match the simulated noise: 1 m at zenith (noise 0.5 m), mapped by elevation
  o.code_noise = CodeNoiseModel::uniform(1.0, 0.0);
  return o;
}

/// Exact pseudoranges plus seeded 0.5 m noise; `fault` adds metres to some satellites.
std::vector<SppObservation> observe(const std::vector<SyntheticSat>& sky, const std::vector<double>& fault,
                                    std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.5);
  std::vector<SppObservation> obs = test::observe(sky, kRx, 30.0);
  for (std::size_t i = 0; i < obs.size(); ++i) {
    obs[i].pseudorange_m += noise(rng);
    obs[i].pseudorange_m += fault[i];
  }
  return obs;
}

bool excluded_exactly(const SppSolution& s, const SatId& a, const SatId& b) {
  const auto has = [&](const SatId& x) { return std::find(s.excluded_fde.begin(), s.excluded_fde.end(), x) != s.excluded_fde.end(); };
  return s.ok && s.excluded_fde.size() == 2 && has(a) && has(b);
}

struct Tally {
  int cases = 0, subsets_found = 0, largest_found = 0, subsets_only = 0;
  double subsets_err_m = 0.0, largest_err_m = 0.0;  // worst 3D error over the cases
};

Tally run_pairs(int n_sats, std::uint64_t sky_seed) {
  const auto sky = synthetic_sky(kRx, n_sats, sky_seed);
  Tally t;
  for (int i = 0; i < n_sats; ++i)
    for (int j = i + 1; j < n_sats; ++j) {
      // two multipath delays between 30 and 60 m, both positive (reflected paths are longer)
      std::vector<double> fault(static_cast<std::size_t>(n_sats), 0.0);
      fault[static_cast<std::size_t>(i)] = 30.0 + 5.0 * ((i + j) % 7);
      fault[static_cast<std::size_t>(j)] = 60.0 - 4.0 * ((i * j) % 8);
      const auto obs = observe(sky, fault, 100 + static_cast<std::uint64_t>(i * n_sats + j));
      const SppSolution sub = solve_spp(obs, geo::Ecef(), 0.0, nullptr, fde_only(SppFde::kSubsets));
      const SppSolution big = solve_spp(obs, geo::Ecef(), 0.0, nullptr, fde_only(SppFde::kLargestResidual));
      const bool a = excluded_exactly(sub, sky[static_cast<std::size_t>(i)].sat, sky[static_cast<std::size_t>(j)].sat);
      const bool b = excluded_exactly(big, sky[static_cast<std::size_t>(i)].sat, sky[static_cast<std::size_t>(j)].sat);
      ++t.cases;
      t.subsets_found += a ? 1 : 0;
      t.largest_found += b ? 1 : 0;
      t.subsets_only += a && !b ? 1 : 0;
      if (sub.ok) t.subsets_err_m = std::max(t.subsets_err_m, (sub.pos.p_m - kRx.p_m).norm());
      if (big.ok) t.largest_err_m = std::max(t.largest_err_m, (big.pos.p_m - kRx.p_m).norm());
    }
  return t;
}

TEST(SppRobust, SubsetFdeFindsBothMultipathSatellitesWhereTheLargestResidualDoesNot) {
  for (const auto& [n, seed] : std::vector<std::pair<int, std::uint64_t>>{{8, 11}, {10, 12}, {12, 13}}) {
    const Tally t = run_pairs(n, seed);
    std::printf("%d sats: %d pairs, subsets found both in %d, largest residual in %d (worst error %.1f m vs %.1f m)\n", n,
                t.cases, t.subsets_found, t.largest_found, t.subsets_err_m, t.largest_err_m);
    EXPECT_GE(t.subsets_found, t.cases * 4 / 5) << n << " satellites";
    EXPECT_GT(t.subsets_only, 0) << n << " satellites";
    EXPECT_GT(t.subsets_found, t.largest_found) << n << " satellites";
  }
}

TEST(SppRobust, LargestResidualMethodFailsOnATwoFaultCase) {
  // one fixed case from the sweep above: the classic method excludes a healthy satellite
  const int n = 8;
  const auto sky = synthetic_sky(kRx, n, 11);
  int shown = 0;
  for (int i = 0; i < n && shown == 0; ++i)
    for (int j = i + 1; j < n && shown == 0; ++j) {
      std::vector<double> fault(n, 0.0);
      fault[static_cast<std::size_t>(i)] = 30.0 + 5.0 * ((i + j) % 7);
      fault[static_cast<std::size_t>(j)] = 60.0 - 4.0 * ((i * j) % 8);
      const auto obs = observe(sky, fault, 100 + static_cast<std::uint64_t>(i * n + j));
      const SppSolution big = solve_spp(obs, geo::Ecef(), 0.0, nullptr, fde_only(SppFde::kLargestResidual));
      if (excluded_exactly(big, sky[static_cast<std::size_t>(i)].sat, sky[static_cast<std::size_t>(j)].sat)) continue;
      const SppSolution sub = solve_spp(obs, geo::Ecef(), 0.0, nullptr, fde_only(SppFde::kSubsets));
      EXPECT_TRUE(excluded_exactly(sub, sky[static_cast<std::size_t>(i)].sat, sky[static_cast<std::size_t>(j)].sat));
      EXPECT_LT((sub.pos.p_m - kRx.p_m).norm(), 5.0);
      ++shown;
    }
  EXPECT_EQ(shown, 1) << "no case where the largest-residual method fails";
}

TEST(SppRobust, Igg3DownweightsAModerateOutlierTheChiSquareTestLetsThrough) {
  const int n = 12;
  const auto sky = synthetic_sky(kRx, n, 21);
  std::vector<double> fault(n, 0.0);
  const auto clean = observe(sky, fault, 5);
  SppOptions plain = fde_only(SppFde::kSubsets);
  const SppSolution ref = solve_spp(clean, geo::Ecef(), 0.0, nullptr, plain);
  ASSERT_TRUE(ref.ok);
  // 4 m on one satellite (2.5-4 sigma): the chi-square test (8 dof) lets most of these through
  double best_gain = 0.0;
  for (int k = 0; k < n; ++k) {
    fault.assign(n, 0.0);
    fault[static_cast<std::size_t>(k)] = 4.0;
    const auto obs = observe(sky, fault, 5);
    const SppSolution a = solve_spp(obs, geo::Ecef(), 0.0, nullptr, plain);
    SppOptions robust = plain;
    robust.robust_igg3 = true;
    const SppSolution b = solve_spp(obs, geo::Ecef(), 0.0, nullptr, robust);
    ASSERT_TRUE(a.ok && b.ok);
    if (!a.excluded_fde.empty()) continue;  // the FDE already took it
    const double ea = (a.pos.p_m - kRx.p_m).norm(), eb = (b.pos.p_m - kRx.p_m).norm();
    EXPECT_LE(eb, ea + 0.05) << "satellite " << k;
    if (b.downweighted > 0) best_gain = std::max(best_gain, ea - eb);
  }
  std::printf("largest IGG-III gain %.2f m\n", best_gain);
  EXPECT_GT(best_gain, 0.2);  // at least one case where the reweighting removes > 0.2 m
}

}  // namespace
}  // namespace pdnav::gnss
