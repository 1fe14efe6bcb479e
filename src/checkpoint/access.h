#pragma once
// Internal: the one door through which checkpoints read and write the
// private state of estimators, smoothers and the EKF (friend of each).
#include "checkpoint/byte_stream.h"
#include "gssm/ekf.h"
#include "gssm/estimator.h"
#include "gssm/smoothers.h"

namespace gssm::internal {

struct CheckpointAccess {
  /// Options, step counter, time, input in force, report, then the method's state.
  static void saveEstimator(const Estimator& e, ByteWriter& out);
  static void loadEstimator(Estimator& e, ByteReader& in);

  static void saveSmoother(const Smoother& s, ByteWriter& out);
  static void loadSmoother(Smoother& s, ByteReader& in, const Model& model);

  static void saveEkf(const ExtendedKalmanFilter& f, ByteWriter& out);
  static void loadEkf(ExtendedKalmanFilter& f, ByteReader& in);

  static void writeOptions(ByteWriter& out, const EstimatorOptions& o);
  static EstimatorOptions readOptions(ByteReader& in);
  static void writeUpdateReport(ByteWriter& out, const UpdateReport& r);
  static UpdateReport readUpdateReport(ByteReader& in);
};

}  // namespace gssm::internal
