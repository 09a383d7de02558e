// A recording at a lower motion-sensor rate (phonesim/sample_rate.h).
#include "pdnav/phonesim/sample_rate.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <variant>

#include <Eigen/Core>

namespace pdnav::phonesim {

namespace {

/// The vectors at_sample_rate averages in a motion-sensor sample: the reading and, for the uncalibrated
/// streams, its bias / drift (nullptr for the calibrated ones); {nullptr, nullptr} for any other line.
std::pair<Eigen::Vector3d*, Eigen::Vector3d*> motion_vectors(Sample& s) {
  return std::visit(
      [](auto& x) -> std::pair<Eigen::Vector3d*, Eigen::Vector3d*> {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, AccelSample>) return {&x.acc_mps2, nullptr};
        else if constexpr (std::is_same_v<T, GyroSample>) return {&x.rate_radps, nullptr};
        else if constexpr (std::is_same_v<T, MagSample>) return {&x.field_ut, nullptr};
        else if constexpr (std::is_same_v<T, UncalAccelSample>) return {&x.acc_mps2, &x.bias_mps2};
        else if constexpr (std::is_same_v<T, UncalGyroSample>) return {&x.rate_radps, &x.drift_radps};
        else if constexpr (std::is_same_v<T, UncalMagSample>) return {&x.field_ut, &x.bias_ut};
        else return {nullptr, nullptr};
      },
      s);
}

}  // namespace

std::vector<Sample> at_sample_rate(const std::vector<Sample>& in, double rate_hz) {
  if (!(rate_hz > 0.0 && rate_hz <= 1e9)) throw std::invalid_argument("at_sample_rate: the rate must be in (0, 1e9] Hz");
  const TimeNs block_ns = static_cast<TimeNs>(std::llround(1e9 / rate_hz));  // >= 1 ns
  struct Block {
    bool open = false;
    TimeNs cell = 0;  // the block's cell on the grid
    int n = 0, n_b = 0;  // readings averaged; of them with a stated bias / drift
    Sample last;
    Eigen::Vector3d sum_a = Eigen::Vector3d::Zero(), sum_b = Eigen::Vector3d::Zero();
  };
  std::array<Block, std::variant_size_v<Sample>> blocks;
  constexpr TimeNs kNoGrid = std::numeric_limits<TimeNs>::min();
  std::array<TimeNs, std::variant_size_v<Sample>> grid0_ns;
  grid0_ns.fill(kNoGrid);
  std::vector<Sample> out;
  out.reserve(in.size());
  const auto flush = [&](Block& b) {
    if (!b.open) return;
    Sample s = b.last;
    if (const auto [a, bias] = motion_vectors(s); a) {
      *a = b.sum_a / b.n;
      // a bias the recording does not state (NaN: Sensor Logger's uncalibrated files) stays unstated
      if (bias) *bias = b.n_b > 0 ? Eigen::Vector3d(b.sum_b / b.n_b) : Eigen::Vector3d::Constant(std::nan(""));
    }
    out.push_back(std::move(s));
    b = Block{};
  };
  for (Sample s : in) {
    const auto [pa, pb] = motion_vectors(s);
    const bool vec = pa != nullptr;
    const Eigen::Vector3d va = vec ? *pa : Eigen::Vector3d::Zero(), vb = pb ? *pb : Eigen::Vector3d::Zero();
    const bool decimated = std::holds_alternative<RotationVectorSample>(s) || std::holds_alternative<GameRotationVectorSample>(s) ||
                           std::holds_alternative<OrientationSample>(s);
    if (!vec && !decimated) {
      out.push_back(std::move(s));
      continue;
    }
    Block& b = blocks[s.index()];
    const TimeNs t = sample_time_ns(s);
    // blocks on a fixed grid of 1 / rate from the stream's first sample: the output rate is the
    // rate asked for whatever the input's (a block of 2 or 3 samples alternates at 50 -> 20 Hz)
    if (grid0_ns[s.index()] == kNoGrid) grid0_ns[s.index()] = t;
    const TimeNs cell = t >= grid0_ns[s.index()] ? (t - grid0_ns[s.index()]) / block_ns : -1;
    if (b.open && (cell != b.cell || cell < 0)) flush(b);
    if (!b.open) b.open = true, b.cell = cell;
    if (vec && va.allFinite()) {
      b.sum_a += va, ++b.n, b.last = s;
      if (vb.allFinite()) b.sum_b += vb, ++b.n_b;
    } else if (!vec) {
      b.n = 1, b.last = s;
    }
    if (b.n == 0) b = Block{};  // a non-finite reading alone: dropped (the block restarts)
  }
  for (Block& b : blocks) flush(b);
  std::stable_sort(out.begin(), out.end(), [](const Sample& x, const Sample& y) { return sample_time_ns(x) < sample_time_ns(y); });
  return out;
}

}  // namespace pdnav::phonesim
