// The gait lag of a uniformly sampled series (internal to pdr/): the lag with the largest
// normalised (Pearson) autocorrelation, as in Rai et al., MobiCom 2012 (Zee) and Moe-Nilssen &
// Helbostad, J. Biomech. 2004. Used by the motion classifier (|a| bin means: gait or vehicle)
// and the step detector (a run's stride).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace pdnav::pdr::detail {

struct BestLag {
  std::size_t lag = 0;  // 0: no lag in the range had variance on both sides
  double corr = -1.0;
};

/// The lag in [max(1, lag_min), min(lag_max, x.size() - 1)] whose Pearson correlation between
/// x[i] and x[i + lag] (over the overlap) is largest; lags without variance on either side are
/// passed over.
inline BestLag best_autocorrelation(const std::vector<double>& x, std::size_t lag_min, std::size_t lag_max) {
  BestLag best;
  const std::size_t n = x.size();
  if (n < 2) return best;
  for (std::size_t lag = std::max<std::size_t>(1, lag_min); lag <= std::min(lag_max, n - 1); ++lag) {
    const std::size_t m = n - lag;
    double ma = 0.0, mb = 0.0;
    for (std::size_t i = 0; i < m; ++i) ma += x[i], mb += x[i + lag];
    ma /= static_cast<double>(m);
    mb /= static_cast<double>(m);
    double ab = 0.0, aa = 0.0, bb = 0.0;
    for (std::size_t i = 0; i < m; ++i) {
      const double a = x[i] - ma, b = x[i + lag] - mb;
      ab += a * b, aa += a * a, bb += b * b;
    }
    if (aa > 0.0 && bb > 0.0 && ab / std::sqrt(aa * bb) > best.corr) best = {lag, ab / std::sqrt(aa * bb)};
  }
  return best;
}

}  // namespace pdnav::pdr::detail
