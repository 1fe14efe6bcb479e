#pragma once
// The IMU's attitude at the start of a log from the data alone (issue #37,
// point 5; docs/DESIGN.md §12): no hand-set attitude, at rest or in motion.
// Two directions known in both frames fix a rotation (Wahba's problem):
//  * the specific force, mean over the first `window` seconds in the IMU's
//    axes, against a − g in NED (a: the mean acceleration over that window
//    from the GNSS velocities; 0 for a car at rest) — roll and pitch;
//  * the vehicle's forward axis (R_vbᵀ·e_x in the IMU's axes) against the
//    GNSS track: the velocity at the start if the car moves (faster than
//    `moving_speed`), else the direction to the first fix `track_distance`
//    from the start (the car pulling away), in 3-D — yaw. When the fixes
//    stop before that (a gap longer than `track_gap`: an outage soon after
//    pulling away), the direction to the last fix before the gap, if it is
//    `min_track_distance` from the start: a chord across the gap would
//    average the turns the car made in it.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "gssm/core/data.h"
#include "gssm/models/strapdown.h"

namespace gssm::models {

struct InsStartOptions {
  /// s of IMU and GNSS averaged at the start: the mean acceleration is the
  /// change of the GNSS velocity over it (its noise falls as the window grows)
  double window = 3.0;
  double moving_speed = 1.0;    ///< m/s: faster is "in motion" (the track from the velocity)
  double track_distance = 3.0;  ///< m: at rest, the track from the first fix this far away
  double track_gap = 1.0;           ///< s: fixes further apart than this end the pulling-away track
  double min_track_distance = 1.0;  ///< m: ... if its last fix before the gap is this far from the start
};

struct InsStart {
  Eigen::Matrix3d R_nb = Eigen::Matrix3d::Identity();  ///< the IMU's attitude at t0
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  ///< of the GNSS antenna at t0, NED (m/s)
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< of the GNSS antenna at t0, NED (m), from the same fit
  bool moving = false;                                 ///< the track came from the velocity
  double track_yaw = 0;                                ///< the vehicle's heading used (rad)
};

/// The rotation R minimizing Σ w_i‖nav_i − R·body_i‖² (the SVD solution of
/// Wahba's problem, a proper rotation). InvalidArgument for fewer than two
/// non-parallel pairs.
Eigen::Matrix3d wahbaRotation(const std::vector<Eigen::Vector3d>& body, const std::vector<Eigen::Vector3d>& nav,
                              const std::vector<double>& weights);

/// The start at t0 from IMU rows (t, gyro, accel: the model's inputs) and
/// GNSS fixes (times and NED positions, in time order), R_vb the IMU →
/// vehicle rotation. InputError naming what is missing (no IMU or GNSS in
/// the window, no fix far enough to give a track).
InsStart insStart(double t0, const std::vector<Input>& imu, const std::vector<double>& fix_t,
                  const std::vector<Eigen::Vector3d>& fix_ned, const Eigen::Matrix3d& R_vb,
                  const strapdown::NavFrame& frame, const InsStartOptions& options = {});

}  // namespace gssm::models
