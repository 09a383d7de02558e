// Heading: (a) the rotation vector's phone->ENU(magnetic) orientation, walking direction =
// a phone axis projected on the horizontal, turned to true north with the WMM declination;
// (b) APT's gyro re-orientation (Zhu/Li/Chen 2013, Sec. V-B): gravity from averaged
// acceleration while walking straight, gyro angular displacement projected on gravity = turn
// angle about the vertical; turns are reported when it passes 30 degrees.
#pragma once
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "pdnav/geo/events.h"
#include "pdnav/geo/samples.h"
#include "pdnav/pdr/step_detector.h"
#include "pdnav/pdr/time_window.h"

namespace pdnav::pdr {

/// Where the phone is carried: which phone axis points in the walking direction.
/// Android axes: +X right, +Y top of the screen, +Z out of the screen.
enum class Mount {
  kAuto,            // estimated from the motion (placement + walking direction, docs/pdr.md)
  kChestCameraOut,  // chest, top up, camera (back) facing forward: forward = -Z
  kChestScreenOut,  // chest, top up, screen facing forward: forward = +Z
  kHandheld,        // held in front, screen up, top ahead: forward = +Y
};
/// The phone-frame unit vector that points where the user walks for a mount (kAuto: +Y, the
/// reference axis the estimated walking-direction offset is measured from).
Eigen::Vector3d forward_axis(Mount mount);
/// "auto", "chest" (= chest-camera-out), "chest-camera-out", "chest-screen-out", "hand" /
/// "handheld"; throws std::invalid_argument naming the accepted values otherwise.
Mount mount_from_string(const std::string& s);
const char* to_string(Mount m);

/// APT Sec. V-B parameters for the gyro re-orientation and turn reports.
struct TurnOptions {
  double window_s = 1.0;                         // angular-displacement window (about one stride)
  double straight_threshold_rad = 15 * kDegToRad;  // |displacement| in a window below this = straight
  double report_threshold_rad = 30 * kDegToRad;  // APT: a turn is reported past 30 degrees
  double gap_reset_s = 0.5;                      // gyro/accel gap that resets the integration
  // Attitude for the reference axis' yaw and the compass's gravity: gyro-propagated, pulled
  // toward the specific force with this time constant (Mahony, Hamel, Pflimlin, IEEE TAC 2008;
  // as the placement's tilt filter). A phone in a pocket or a swinging hand tilts by tens of
  // degrees every stride: about APT's held 1 s mean the yaw and the compass mix that swing
  // differently, so their sum (the heading offset) never holds still. 0 = APT's 1 s mean.
  double tilt_tau_s = 1.0;
};

struct HeadingOptions {
  Mount mount = Mount::kChestCameraOut;  // brief: chest mount, walking direction = phone -Z
  double rv_max_age_s = 0.5;             // rotation vector older than this is not used
  double rv_sigma_rad = 15 * kDegToRad;  // heading 1-sigma when the RV reports no accuracy
  double min_horizontal = 0.25;          // |horizontal part| of the forward axis; below: unusable
  double initial_heading_rad = 0.0;      // true heading at start when only the gyro is available
  double initial_sigma_rad = kPi;        // its 1-sigma (unknown by default)
  double gyro_drift_radps = 0.2 * kDegToRad;  // heading sigma growth in gyro-only mode
  double compass_tau_s = 10.0;           // complementary filter gyro<-compass time constant
  double compass_sigma_rad = 20 * kDegToRad;
  TurnOptions turn;
};

/// Magnetic heading (clockwise from magnetic north, [0, 2pi)) of a phone axis under a
/// phone->ENU rotation-vector quaternion (x, y, z, w); nullopt when the axis is near vertical
/// or the quaternion is not finite/normalisable.
std::optional<double> rotation_vector_heading_rad(const Eigen::Vector4d& quat_xyzw,
                                                  const Eigen::Vector3d& forward_phone,
                                                  double min_horizontal = 0.25);

/// Tilt-compensated compass: magnetic heading of a phone axis from the field and the gravity
/// direction (both in phone axes); nullopt when degenerate.
std::optional<double> compass_heading_rad(const Eigen::Vector3d& field_phone, const Eigen::Vector3d& up_phone,
                                          const Eigen::Vector3d& forward_phone, double min_horizontal = 0.25);

/// APT's gyro re-orientation: integrates the gyro about the estimated gravity (yaw, positive =
/// counter-clockwise seen from above = left) and reports turns. With tilt_tau_s > 0 it also
/// keeps a gyro-propagated, accelerometer-levelled attitude: the instantaneous gravity and the
/// yaw of one phone axis (axis_yaw_rad(), the heading fusion's reference axis).
class GyroTurnTracker {
 public:
  explicit GyroTurnTracker(const TurnOptions& options = {});

  void feed(const AccelSample& s);
  void feed(const GyroSample& s);

  /// Integrated yaw about the vertical since start (rad, left positive); valid once gravity is known.
  double yaw_rad() const { return yaw_rad_; }
  /// axis_yaw_rad() as it was at t_ns (linear between the gyro samples kept, the last 3
  /// windows); nullopt when t_ns is outside them.
  std::optional<double> axis_yaw_rad_at(TimeNs t_ns) const;
  /// The phone axis whose heading axis_yaw_rad() follows (the heading filter's reference axis).
  void set_yaw_axis(const Eigen::Vector3d& axis_phone);
  /// Yaw (rad, left positive, continuous) of the yaw axis' horizontal projection in the
  /// gyro-propagated attitude (tilt_tau_s > 0), else yaw_rad(). Unlike the integral of the
  /// vertical rate, it has no coning drift: a phone swung about two axes at once (a running
  /// pocket) accumulates the area its swing encloses in that integral, several deg/s. Held
  /// while the axis is within ~12 deg of the vertical.
  double axis_yaw_rad() const { return tilt_ok_ ? axis_yaw_rad_ : yaw_rad_; }
  bool has_gravity() const { return have_gravity_; }
  /// Unit "up" vector in phone axes: the tilt filter's instantaneous gravity (tilt_tau_s > 0),
  /// else the mean specific force while walking straight.
  const Eigen::Vector3d& up_phone() const { return tilt_ok_ ? tilt_up_ : up_; }
  bool straight() const { return state_ == State::kStraight; }
  std::vector<PdrTurn> take_turns();
  const SampleCounters& gyro_counters() const { return gyro_counters_; }
  const SampleCounters& accel_counters() const { return accel_counters_; }

 private:
  enum class State { kStraight, kTurning, kSettling };
  struct YawAt {
    TimeNs t_ns;
    double yaw;
    double axis_yaw;  // axis_yaw_rad() then
  };
  void update_turn_state(TimeNs t_ns);
  bool window_straight() const;
  double mean_yaw(TimeNs from_ns, TimeNs to_ns) const;
  void trim_history(TimeNs t_ns);

  TurnOptions opt_;
  SampleCounters gyro_counters_, accel_counters_;
  // gravity: running mean of the accelerometer over window_s
  TimeWindowSum<Eigen::Vector3d> acc_window_;
  bool have_acc_last_ = false;
  TimeNs acc_last_ns_ = 0;
  Eigen::Vector3d up_ = Eigen::Vector3d::UnitZ();
  bool have_gravity_ = false;
  Eigen::Vector3d tilt_up_ = Eigen::Vector3d::UnitZ();  // tilt filter (tilt_tau_s > 0): up in phone axes
  bool tilt_ok_ = false;
  Eigen::Quaterniond attitude_ = Eigen::Quaterniond::Identity();  // phone -> level gyro frame
  Eigen::Vector3d yaw_axis_ = Eigen::Vector3d::UnitY();
  double axis_yaw_rad_ = 0.0;   // continuous
  double axis_yaw_wrapped_ = 0.0;
  bool axis_yaw_init_ = false;
  void update_axis_yaw();
  // gyro integration
  bool have_gyro_last_ = false;
  TimeNs gyro_last_ns_ = 0;
  Eigen::Vector3d gyro_last_ = Eigen::Vector3d::Zero();
  double yaw_rad_ = 0.0;
  std::deque<YawAt> history_;  // yaw over the last 3 windows
  // turn state machine
  State state_ = State::kStraight;
  TimeNs turn_start_ns_ = 0;
  TimeNs settle_since_ns_ = 0;
  TimeNs last_turn_end_ns_ = 0;
  double anchor_yaw_ = 0.0;
  std::vector<PdrTurn> turns_;
};

}  // namespace pdnav::pdr
