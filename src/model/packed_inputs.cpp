#include "gssm/model/packed_inputs.h"

#include <algorithm>
#include <string>

#include "gssm/core/error.h"
#include "gssm/core/time.h"

namespace gssm {

namespace {
// One step's readings being gathered: (duration, reading) slots.
struct Pack {
  double start = 0;
  std::vector<std::pair<double, const Eigen::VectorXd*>> slots;
  Input close(int per_step, Eigen::Index raw, const Eigen::VectorXd& held) const {
    Input in{start, Eigen::VectorXd::Zero((raw + 1) * per_step)};
    const Eigen::VectorXd* last = &held;
    for (int j = 0; j < per_step; ++j) {
      const bool filled = j < static_cast<int>(slots.size());
      if (filled) last = slots[static_cast<std::size_t>(j)].second;
      in.u[j * (raw + 1)] = filled ? slots[static_cast<std::size_t>(j)].first : 0.0;
      in.u.segment(j * (raw + 1) + 1, raw) = *last;
    }
    return in;
  }
};
}  // namespace

std::vector<Input> packInputs(const std::vector<Input>& raw, std::vector<double> cuts, int per_step, double t0) {
  if (per_step < 1) throw InvalidArgument("packInputs: per_step = " + std::to_string(per_step) + ": expected >= 1");
  if (raw.empty()) return {};
  const Eigen::Index width = raw.front().u.size();
  for (std::size_t i = 0; i < raw.size(); ++i)
    if (raw[i].u.size() != width || (i > 0 && !(raw[i].t > raw[i - 1].t)))
      throw InvalidArgument("packInputs: input " + std::to_string(i) + " has another size or is not after the previous");
  std::sort(cuts.begin(), cuts.end());
  const Eigen::VectorXd none = Eigen::VectorXd::Zero(width);
  const Eigen::VectorXd* held = &none;  // the reading in force
  std::size_t ri = 0, ci = 0;
  const auto atOrBefore = [](double a, double t) { return a <= t || sameTime(a, t); };
  // Past the events at or before t: the reading then in force is held.
  const auto passTo = [&](double t) {
    for (; ri < raw.size() && atOrBefore(raw[ri].t, t); ++ri) held = &raw[ri].u;
    while (ci < cuts.size() && atOrBefore(cuts[ci], t)) ++ci;
  };
  passTo(t0);
  std::vector<Input> out;
  Pack pack{t0, {}};
  double now = t0;
  while (ri < raw.size() || ci < cuts.size()) {
    const double tr = ri < raw.size() ? raw[ri].t : INFINITY, tc = ci < cuts.size() ? cuts[ci] : INFINITY;
    const double t = std::min(tr, tc);
    const bool cut = ci < cuts.size() && atOrBefore(tc, tr);
    if (t > now && !sameTime(t, now)) pack.slots.emplace_back(t - now, held), now = t;
    passTo(t);
    if (!cut && static_cast<int>(pack.slots.size()) < per_step) continue;
    if (pack.slots.empty()) continue;  // an event at the step's own start
    out.push_back(pack.close(per_step, width, *held));
    pack = Pack{now, {}};
  }
  if (!pack.slots.empty()) out.push_back(pack.close(per_step, width, *held));
  out.push_back(Pack{now, {}}.close(per_step, width, *held));  // the last state's: holds the reading in force there
  return out;
}

}  // namespace gssm
