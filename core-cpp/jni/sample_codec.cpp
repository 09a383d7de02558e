// One field map per sample type, used in both directions (decode and encode), so the two
// directions cannot disagree. See sample_codec.h for the row layout.
#include "sample_codec.h"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <type_traits>
#include <utility>

namespace pdnav::jni {
namespace {

[[noreturn]] void fail(std::size_t row, const std::string& reason) {
  throw std::invalid_argument("sample batch row " + std::to_string(row) + ": " + reason);
}

/// Reads row fields into a sample.
class Decoder {
 public:
  Decoder(const BatchView& b, std::size_t row) : b_(b), row_(row) {}
  void i(std::size_t k, std::int64_t& v) const { v = b_.ints[row_ * kInts + k]; }
  void i(std::size_t k, int& v) const {
    const std::int64_t x = b_.ints[row_ * kInts + k];
    if (x < std::numeric_limits<int>::min() || x > std::numeric_limits<int>::max()) {
      fail(row_, "integer field " + std::to_string(k) + " out of int range");
    }
    v = static_cast<int>(x);
  }
  void i(std::size_t k, bool& v) const { v = b_.ints[row_ * kInts + k] != 0; }
  void d(std::size_t k, double& v) const { v = b_.doubles[row_ * kDoubles + k]; }
  void s(std::size_t k, std::string& v) const { v = b_.strings[row_ * kStrings + k]; }
  void bytes(std::size_t len_slot, std::vector<std::uint8_t>& v) const {
    const std::int64_t len = b_.ints[row_ * kInts + len_slot];
    if (len < 0 || static_cast<std::size_t>(len) > kBytes) {
      fail(row_, "navigation data length " + std::to_string(len) + " not in 0.." +
                     std::to_string(kBytes));
    }
    const std::int8_t* p = b_.bytes + row_ * kBytes;
    v.resize(static_cast<std::size_t>(len));
    std::transform(p, p + len, v.begin(), [](std::int8_t c) { return static_cast<std::uint8_t>(c); });
  }

 private:
  const BatchView& b_;
  std::size_t row_;
};

/// Writes sample fields into a row.
class Encoder {
 public:
  Encoder(BatchOut& b, std::size_t row) : b_(b), row_(row) {}
  void i(std::size_t k, const std::int64_t& v) { b_.ints[row_ * kInts + k] = v; }
  void i(std::size_t k, const int& v) { b_.ints[row_ * kInts + k] = v; }
  void i(std::size_t k, const bool& v) { b_.ints[row_ * kInts + k] = v ? 1 : 0; }
  void d(std::size_t k, const double& v) { b_.doubles[row_ * kDoubles + k] = v; }
  void s(std::size_t k, const std::string& v) { b_.strings[row_ * kStrings + k] = v; }
  void bytes(std::size_t len_slot, const std::vector<std::uint8_t>& v) {
    if (v.size() > kBytes) {
      fail(row_, "navigation data of " + std::to_string(v.size()) + " bytes exceeds " +
                     std::to_string(kBytes));
    }
    b_.ints[row_ * kInts + len_slot] = static_cast<std::int64_t>(v.size());
    std::int8_t* p = b_.bytes + row_ * kBytes;
    std::transform(v.begin(), v.end(), p, [](std::uint8_t c) { return static_cast<std::int8_t>(c); });
  }

 private:
  BatchOut& b_;
  std::size_t row_;
};

// Field maps. Io is Decoder (S non-const) or Encoder (S const).
template <class Io, class V3>
void vec3(Io& io, std::size_t k0, V3& v) {
  io.d(k0, v[0]);
  io.d(k0 + 1, v[1]);
  io.d(k0 + 2, v[2]);
}

template <class Io, class S>
void gnss_raw_fields(Io& io, S& s);

template <class Io, class S>
void fields(Io& io, S& s) {
  using T = std::remove_const_t<S>;
  if constexpr (std::is_same_v<T, AccelSample>) {
    io.i(0, s.utc_ms); vec3(io, 0, s.acc_mps2);
  } else if constexpr (std::is_same_v<T, GyroSample>) {
    io.i(0, s.utc_ms); vec3(io, 0, s.rate_radps);
  } else if constexpr (std::is_same_v<T, MagSample>) {
    io.i(0, s.utc_ms); vec3(io, 0, s.field_ut);
  } else if constexpr (std::is_same_v<T, UncalAccelSample>) {
    io.i(0, s.utc_ms); vec3(io, 0, s.acc_mps2); vec3(io, 3, s.bias_mps2);
  } else if constexpr (std::is_same_v<T, UncalGyroSample>) {
    io.i(0, s.utc_ms); vec3(io, 0, s.rate_radps); vec3(io, 3, s.drift_radps);
  } else if constexpr (std::is_same_v<T, UncalMagSample>) {
    io.i(0, s.utc_ms); vec3(io, 0, s.field_ut); vec3(io, 3, s.bias_ut);
  } else if constexpr (std::is_same_v<T, OrientationSample>) {
    io.i(0, s.utc_ms); io.d(0, s.yaw_deg); io.d(1, s.roll_deg); io.d(2, s.pitch_deg);
  } else if constexpr (std::is_same_v<T, PressureSample>) {
    io.i(0, s.utc_ms); io.d(0, s.pressure_pa);
  } else if constexpr (std::is_same_v<T, RotationVectorSample>) {
    io.i(0, s.utc_ms);
    for (std::size_t k = 0; k < 4; ++k) io.d(k, s.quat_xyzw[static_cast<Eigen::Index>(k)]);
    io.d(4, s.heading_accuracy_rad);
  } else if constexpr (std::is_same_v<T, StepDetectorSample>) {
    io.i(0, s.utc_ms);
  } else if constexpr (std::is_same_v<T, StepCounterSample>) {
    io.i(0, s.utc_ms); io.i(1, s.count);
  } else if constexpr (std::is_same_v<T, GnssRawSample>) {
    gnss_raw_fields(io, s);
  } else if constexpr (std::is_same_v<T, FixSample>) {
    io.i(0, s.utc_ms); io.s(0, s.provider);
    io.d(0, s.lat_deg); io.d(1, s.lon_deg); io.d(2, s.alt_m); io.d(3, s.speed_mps);
    io.d(4, s.accuracy_m); io.d(5, s.bearing_deg); io.d(6, s.speed_accuracy_mps);
    io.d(7, s.bearing_accuracy_deg); io.d(8, s.vertical_accuracy_m);
  } else if constexpr (std::is_same_v<T, NavMessageSample>) {
    io.i(0, s.svid); io.i(1, s.type); io.i(2, s.status); io.i(3, s.message_id);
    io.i(4, s.sub_message_id); io.bytes(5, s.data);
  } else if constexpr (std::is_same_v<T, GnssStatusSample>) {
    io.i(0, s.utc_ms); io.i(1, s.signal_count); io.i(2, s.signal_index);
    io.i(3, s.constellation_type); io.i(4, s.svid); io.i(5, s.used_in_fix);
    io.i(6, s.has_almanac); io.i(7, s.has_ephemeris);
    io.d(0, s.carrier_frequency_hz); io.d(1, s.cn0_dbhz); io.d(2, s.azimuth_deg);
    io.d(3, s.elevation_deg); io.d(4, s.baseband_cn0_dbhz);
  } else if constexpr (std::is_same_v<T, AgcSample>) {
    io.i(0, s.utc_ms); io.i(1, s.time_nanos); io.i(2, s.constellation_type);
    io.d(0, s.agc_db); io.d(1, s.carrier_frequency_hz);
  } else if constexpr (std::is_same_v<T, TruthSample>) {
    io.d(0, s.lat_deg); io.d(1, s.lon_deg); io.d(2, s.h_m); io.d(3, s.heading_deg);
  } else if constexpr (std::is_same_v<T, MetaSample>) {
    io.s(0, s.key); io.s(1, s.value);
  } else if constexpr (std::is_same_v<T, GameRotationVectorSample>) {
    io.i(0, s.utc_ms);
    for (std::size_t k = 0; k < 4; ++k) io.d(k, s.quat_xyzw[static_cast<Eigen::Index>(k)]);
  } else if constexpr (std::is_same_v<T, SensorAccuracySample>) {
    io.i(0, s.utc_ms); io.i(1, s.sensor_type); io.i(2, s.accuracy);
  } else {
    static_assert(sizeof(T) == 0, "sample type without a field map");
  }
}

template <class Io, class S>
void gnss_raw_fields(Io& io, S& s) {
  io.i(0, s.utc_ms); io.i(1, s.time_nanos); io.i(2, s.leap_second); io.i(3, s.full_bias_nanos);
  io.i(4, s.hardware_clock_discontinuity_count); io.i(5, s.svid); io.i(6, s.state);
  io.i(7, s.received_sv_time_nanos); io.i(8, s.received_sv_time_uncertainty_nanos);
  io.i(9, s.accumulated_delta_range_state); io.i(10, s.carrier_cycles);
  io.i(11, s.multipath_indicator); io.i(12, s.constellation_type);
  io.i(13, s.chipset_elapsed_realtime_nanos);
  io.d(0, s.time_uncertainty_nanos); io.d(1, s.bias_nanos); io.d(2, s.bias_uncertainty_nanos);
  io.d(3, s.drift_nanos_per_second); io.d(4, s.drift_uncertainty_nanos_per_second);
  io.d(5, s.time_offset_nanos); io.d(6, s.cn0_dbhz); io.d(7, s.pseudorange_rate_mps);
  io.d(8, s.pseudorange_rate_uncertainty_mps); io.d(9, s.accumulated_delta_range_m);
  io.d(10, s.accumulated_delta_range_uncertainty_m); io.d(11, s.carrier_frequency_hz);
  io.d(12, s.carrier_phase); io.d(13, s.carrier_phase_uncertainty); io.d(14, s.snr_db);
  io.d(15, s.agc_db); io.d(16, s.baseband_cn0_dbhz); io.d(17, s.full_inter_signal_bias_nanos);
  io.d(18, s.full_inter_signal_bias_uncertainty_nanos);
  io.d(19, s.satellite_inter_signal_bias_nanos);
  io.d(20, s.satellite_inter_signal_bias_uncertainty_nanos);
  io.s(0, s.code_type);
}

/// Default-constructs the variant alternative with the given index.
template <std::size_t... I>
Sample make_sample(std::size_t index, std::index_sequence<I...>) {
  Sample out;
  static_cast<void>(((index == I ? (out.template emplace<I>(), true) : false) || ...));
  return out;
}

}  // namespace

Sample decode_row(const BatchView& b, std::size_t i) {
  const std::int32_t kind = b.kinds[i];
  if (kind < 0 || kind >= kKinds) fail(i, "unknown sample kind " + std::to_string(kind));
  Sample s = make_sample(static_cast<std::size_t>(kind), std::make_index_sequence<std::variant_size_v<Sample>>{});
  const Decoder dec(b, i);
  std::visit([&](auto& x) {
    x.t_ns = b.t_ns[i];
    fields(dec, x);
  }, s);
  return s;
}

void encode_row(const Sample& s, BatchOut& b, std::size_t i) {
  b.kinds[i] = static_cast<std::int32_t>(s.index());
  b.t_ns[i] = sample_time_ns(s);
  std::fill(b.ints + i * kInts, b.ints + (i + 1) * kInts, std::int64_t{0});
  std::fill(b.doubles + i * kDoubles, b.doubles + (i + 1) * kDoubles, 0.0);
  std::fill(b.strings + i * kStrings, b.strings + (i + 1) * kStrings, std::string());
  std::fill(b.bytes + i * kBytes, b.bytes + (i + 1) * kBytes, std::int8_t{0});
  Encoder enc(b, i);
  std::visit([&](const auto& x) { fields(enc, x); }, s);
}

}  // namespace pdnav::jni
