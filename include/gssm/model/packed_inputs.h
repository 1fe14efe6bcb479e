#pragma once
// Packed inputs (docs/DESIGN.md §12, "States between IMU samples"): a model
// whose state is not kept at every input sample (an INS with states at
// 10 Hz over a 100 Hz IMU) takes, as one step's input, the readings in
// force over that step, each with its duration:
//
//   u = [dt_1, r_1, dt_2, r_2, …, dt_N, r_N]     (r_j: one raw reading)
//
// The packed input at time s holds from s: its model integrates its first
// dt seconds (dt = the step's, whatever the pack's total), the last
// reading held past the pack's end. Slots past the last reading have
// dt_j = 0 and repeat it.
#include <vector>

#include "gssm/core/data.h"

namespace gssm {

/// Packs raw inputs, each held from its time (rates), into steps of at most
/// `per_step` readings. A step also ends at every time of `cuts` (the
/// measurements': each then falls on a state) after t0. The packed inputs
/// start at t0 and at every step's end, the last at the last raw input or
/// cut, so the states sit at those times; a reading is split where a cut
/// falls inside its interval. Throws InvalidArgument for per_step < 1, raw
/// inputs of different sizes or out of order.
std::vector<Input> packInputs(const std::vector<Input>& raw, std::vector<double> cuts, int per_step, double t0);

/// The size of one raw reading in a packed input of `packed_size` entries
/// and `per_step` slots ([dt, reading] each).
inline Eigen::Index packedReadingSize(Eigen::Index packed_size, int per_step) { return packed_size / per_step - 1; }

/// The readings a packed input holds (its slots with a duration).
inline int packedReadings(const Eigen::VectorXd& u, int per_step) {
  const Eigen::Index width = u.size() / per_step;
  int n = 0;
  for (int j = 0; j < per_step; ++j) n += u[j * width] > 0 ? 1 : 0;
  return n;
}

/// The raw readings of a packed input u of `per_step` slots (raw size
/// u.size() / per_step − 1) with their durations, as f integrates them over dt:
/// calls step(reading, duration) in order until dt is used up.
template <class Step>
void forEachPackedReading(const Eigen::VectorXd& u, int per_step, double dt, Step&& step) {
  const Eigen::Index raw = packedReadingSize(u.size(), per_step), width = raw + 1;
  double left = dt;
  for (int j = 0; j < per_step && left > 0; ++j) {
    const double dj = u[j * width];
    const bool last = j + 1 == per_step || !(u[(j + 1) * width] > 0);
    const double h = last ? left : std::min(dj, left);
    if (h > 0) step(u.segment(j * width + 1, raw), h);
    left -= h;
  }
}

}  // namespace gssm
