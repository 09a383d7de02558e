// Code noise model per constellation and band (issue 15): the parameter lookup, and the
// residuals at a known position that tools/gnss-noise-fit learns from, checked on a simulated
// sky with a known noise per system, unknown clocks and a truth whose height is 40 m off.
#include <cmath>
#include <map>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/geo/frames.h"
#include "pdnav/gnss/measurements.h"
#include "pdnav/gnss/noise_model.h"
#include "pdnav/gnss/solver_synthetic.h"
#include "pdnav/gnss/spp.h"

namespace pdnav::gnss {
namespace {

const geo::Geodetic kRxGeo = geo::Geodetic::from_deg(37.4, -122.1, 10.0);

TEST(NoiseModel, ParametersPerConstellationAndBand) {
  CodeNoiseModel m;
  m.gps_l1 = {1.0, 10.0};
  m.gps_l5 = {2.0, 20.0};
  m.glonass_g1 = {3.0, 30.0};
  m.galileo_e5a = {4.0, 40.0};
  EXPECT_EQ(signal_band(1575.42e6), SignalBand::kL1);
  EXPECT_EQ(signal_band(1176.45e6), SignalBand::kL5);
  EXPECT_EQ(signal_band(kNaN), SignalBand::kL1);  // old logs without a carrier frequency
  EXPECT_EQ(m.params(Constellation::kQzss, SignalBand::kL5).a_m2, 2.0);  // QZSS shares GPS's
  EXPECT_EQ(m.params(Constellation::kGlonass, SignalBand::kL5).a_m2, 3.0);  // G1 only
  EXPECT_EQ(m.params(Constellation::kGalileo, SignalBand::kL5).a_m2, 4.0);
  EXPECT_NEAR(m.variance_m2(Constellation::kGps, 1176.45e6, 30.0, kPi / 2), 2.0 + 20.0e-3, 1e-12);
  EXPECT_GT(m.variance_m2(Constellation::kGps, 1575.42e6, 30.0, 0.2), m.variance_m2(Constellation::kGps, 1575.42e6, 30.0, 1.2));
  // the default model: a GLONASS code is noisier than a GPS one, an L5 code quieter than L1
  const CodeNoiseModel d;
  EXPECT_GT(d.zenith_variance_m2(Constellation::kGlonass, SignalBand::kL1, 35.0),
            d.zenith_variance_m2(Constellation::kGps, SignalBand::kL1, 35.0));
  EXPECT_LT(d.zenith_variance_m2(Constellation::kGps, SignalBand::kL5, 35.0),
            d.zenith_variance_m2(Constellation::kGps, SignalBand::kL1, 35.0));
}

TEST(NoiseModel, TheWhiteTermIsTheShareTheSmoothingRatioScalesInEitherBandOrTheCombination) {
  CodeNoiseModel m;
  m.gps_l1 = {1.0, 10000.0};
  m.gps_l5 = {2.0, 2000.0};
  const double l1 = 1575.42e6;
  // one band: b 10^(-C/N0/10), and the whole variance is a / sin^2 el + ratio x that
  EXPECT_NEAR(code_white_variance_m2(m, Constellation::kGps, l1, false, 30.0, kNaN), 10.0, 1e-12);
  EXPECT_NEAR(code_variance_m2(m, Constellation::kGps, l1, false, 30.0, kNaN, kPi / 6, 0.25), 4.0 + 2.5, 1e-12);
  // the L1/L5 combination: alpha^2 and beta^2 of each band's own term
  const double w_if = kIfAlpha * kIfAlpha * 10.0 + kIfBeta * kIfBeta * 2.0;
  EXPECT_NEAR(code_white_variance_m2(m, Constellation::kGps, l1, true, 30.0, 30.0), w_if, 1e-9);
  const double v_if = code_variance_m2(m, Constellation::kGps, l1, true, 30.0, 30.0, kPi / 2, 0.5);
  EXPECT_NEAR(v_if, kIfAlpha * kIfAlpha * 1.0 + kIfBeta * kIfBeta * 2.0 + 0.5 * w_if, 1e-9);
  EXPECT_NEAR(v_if, iono_free_variance_m2(m, Constellation::kGps, 30.0, 30.0, kPi / 2, 0.5), 1e-9);
  // a combination without its L5 C/N0 is weighted as its L1 code
  EXPECT_NEAR(code_variance_m2(m, Constellation::kGps, l1, true, 30.0, kNaN, kPi / 2), 11.0, 1e-12);
  EXPECT_NEAR(code_white_variance_m2(m, Constellation::kGps, l1, true, 30.0, kNaN), 10.0, 1e-12);
}

struct Spread {
  std::map<Constellation, double> rms_m;
  std::map<Constellation, int> n;
};

/// 400 epochs of a 12-satellite GPS + Galileo sky, code noise 3 m (GPS) and 1 m (Galileo),
/// a random receiver clock and ISB per epoch; residuals at a truth `height_error_m` too high.
Spread simulate(double height_error_m, bool estimate_height) {
  const geo::Ecef rx = geo::to_ecef(kRxGeo);
  geo::Geodetic off = kRxGeo;
  off.h_m += height_error_m;
  const geo::Ecef truth = geo::to_ecef(off);
  SppOptions opt;
  opt.ionosphere = false;
  opt.troposphere = false;
  TruthResidualOptions ro;
  ro.estimate_height = estimate_height;
  std::mt19937_64 rng(15);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::map<Constellation, double> sum2;
  Spread s;
  for (int epoch = 0; epoch < 400; ++epoch) {
    const auto sky = synthetic_sky(rx, 12, 1000 + static_cast<std::uint64_t>(epoch),
                                   {Constellation::kGps, Constellation::kGalileo});
    const double clock_m = 1e5 * unit(rng), isb_m = 50.0 * unit(rng);
    std::vector<SppObservation> obs;
    for (const auto& sat : sky) {
      SppObservation o;
      o.sat = sat.sat;
      o.cn0_dbhz = 35.0;
      o.state = sat.state;
      const bool gal = sat.sat.sys == Constellation::kGalileo;
      o.pseudorange_m = sagnac_range_m(sat.state.pos.p_m, rx.p_m) + clock_m + (gal ? isb_m : 0.0) -
                        kSpeedOfLight_mps * (sat.state.clock_bias_s - sat.state.group_delay_s) +
                        (gal ? 1.0 : 3.0) * unit(rng);
      obs.push_back(o);
    }
    for (const TruthResidual& r : residuals_at_truth(obs, truth, 345600.0, nullptr, opt, ro)) {
      sum2[r.sat.sys] += r.residual_m * r.residual_m;
      ++s.n[r.sat.sys];
    }
  }
  for (const auto& [sys, v] : sum2) s.rms_m[sys] = std::sqrt(v / s.n[sys]);
  return s;
}

TEST(NoiseModel, ResidualsAtTruthRecoverTheSimulatedNoiseOfEachSystem) {
  const Spread s = simulate(40.0, true);
  ASSERT_EQ(s.n.at(Constellation::kGps), 2400);
  ASSERT_EQ(s.n.at(Constellation::kGalileo), 2400);
  // the clock (leave-one-out median of 5 others, its variance divided out) and the height are
  // removed: the spread of each system is its simulated sigma within 10 %
  EXPECT_NEAR(s.rms_m.at(Constellation::kGps), 3.0, 0.3);
  EXPECT_NEAR(s.rms_m.at(Constellation::kGalileo), 1.0, 0.1);
  // a 40 m height error left in the truth inflates the residuals (up to 40 m x the spread of
  // sin(el) within a system): estimating it is what makes a biased truth usable
  const Spread biased = simulate(40.0, false);
  EXPECT_GT(biased.rms_m.at(Constellation::kGalileo), 3.0);
}

// FrequencyMode::kBest puts L1 and L5 codes of one system into one epoch: the L5 codes carry
// the receiver's L1-L5 bias (2.35 km on the GSDC Pixel 5), which the SPP estimates as a clock
// of its own per band.
TEST(NoiseModel, SppSolvesOneReceiverClockPerBand) {
  const geo::Ecef rx = geo::to_ecef(kRxGeo);
  const auto sky = synthetic_sky(rx, 10, 77);
  std::vector<SppObservation> obs;
  for (std::size_t i = 0; i < sky.size(); ++i) {
    SppObservation o;
    o.sat = sky[i].sat;
    o.cn0_dbhz = 40.0;
    o.state = sky[i].state;
    o.state.group_delay_s = 0.0;
    const bool l5 = i % 2 == 1;
    o.carrier_hz = l5 ? 1176.45e6 : 1575.42e6;
    o.pseudorange_m = sagnac_range_m(o.state.pos.p_m, rx.p_m) + 30.0 + (l5 ? 2350.0 : 0.0) -
                      kSpeedOfLight_mps * o.state.clock_bias_s;
    obs.push_back(o);
  }
  SppOptions opt;
  opt.ionosphere = false;
  opt.troposphere = false;
  const SppSolution s = solve_spp(obs, geo::Ecef(), 345600.0, nullptr, opt);
  ASSERT_TRUE(s.ok) << s.reason;
  EXPECT_LT((s.pos.p_m - rx.p_m).norm(), 0.01);
  EXPECT_EQ(s.clock_system, Constellation::kGps);
  EXPECT_EQ(s.clock_band, SignalBand::kL1);
  EXPECT_NEAR(s.clock_m, 30.0, 0.01);
  ASSERT_EQ(s.isb_l5_m.count(Constellation::kGps), 1u);
  EXPECT_NEAR(s.isb_l5_m.at(Constellation::kGps), 2350.0, 0.01);
  EXPECT_TRUE(s.isb_m.empty());
}

}  // namespace
}  // namespace pdnav::gnss
