#pragma once
// The GSSM model interface (docs/DESIGN.md §1, eq. 1). A model splits its state into a
// time-series part x_c (dim n_c) and a constant part x_b (dim n_b):
//
//   x_c(k+1) = f(x_c(k), x_b, u_k, T) + q_c(k),   q_c ~ N(0, Q(T))
//   y(k)     = h(x_c(k), x_b) + r(k),             r   ~ N(0, R)
//   x_c(0) ~ N(x_c⁺, P_c),  x_b ~ N(x_b⁺, P_b)
//
// The same model object drives the EKF, the batch solver and the smoothers.
#include <Eigen/Core>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gssm/core/data.h"
#include "gssm/core/gaussian.h"
#include "gssm/core/robust_loss.h"

namespace gssm {

/// One sensor stream of a model (docs/DESIGN.md §9). A model has at least
/// one; the default channel of a one-sensor model is "y", built from its
/// measurement names and R.
struct MeasurementChannel {
  std::string name;                     ///< unique among the model's channels
  std::vector<std::string> components;  ///< component names; the dimension is their number
  Eigen::MatrixXd R;                    ///< noise covariance
  RobustLoss loss;                      ///< on the whitened residual (default: none, Gaussian)
  std::vector<int> angles;              ///< components that are angles: residuals wrapped to (−π, π]
  /// EKF: a measurement whose NIS exceeds this is rejected (0: no gate),
  /// e.g. the χ² 0.999 quantile of the channel's dimension.
  double ekf_gate = 0;
  /// The constants h on this channel can depend on, ascending (empty: all
  /// of x_b). Its Jacobian on x_b is zero in every other column at every
  /// point, so the batch solver reads only these (a link's range: its own
  /// bias and the scale, 2 of 25); the Jacobian tests check the claim.
  std::vector<int> constants;
  /// A measurement that brings its own covariance (Measurement::R: a GNSS
  /// fix's reported sds) is used with it times this variance factor — the
  /// reported sds scaled by a number the log can teach (learnable where a
  /// model exposes it, e.g. strapdown_ins's gnss_sd_scale). The channel's
  /// own R is not scaled.
  double own_R_scale = 1;
  /// How many known values a measurement on this channel carries beside y
  /// (Measurement::regressors), which h reads: 0 on most channels; h of such
  /// a channel is Model::hWith (a GNSS velocity: the gyro's mean reading
  /// and the velocity's rate of change).
  int regressors = 0;
  int dim() const { return static_cast<int>(components.size()); }
  /// The noise covariance of a measurement on this channel that brings
  /// `own` (Measurement::R; empty: none): own_R_scale·own, else R.
  Eigen::MatrixXd covarianceOf(const Eigen::MatrixXd& own) const { return own.size() ? own_R_scale * own : R; }
};

struct ModelDims {
  int nc = 0;  ///< time-series state x_c
  int nb = 0;  ///< constant state x_b
  int nu = 0;  ///< input u
  int ny = 0;  ///< measurement y
};

/// Component names, used as CSV column names (must be unique, no commas).
struct ModelNames {
  std::vector<std::string> state;        ///< n_c names
  std::vector<std::string> constants;    ///< n_b names
  std::vector<std::string> input;        ///< n_u names
  std::vector<std::string> measurement;  ///< n_y names
};

/// Noise and priors shared by every model.
struct ModelNoise {
  double T = 1.0;           ///< nominal step (s)
  Eigen::MatrixXd Q;        ///< process noise covariance of one nominal step (n_c×n_c)
  Eigen::MatrixXd R;        ///< measurement noise covariance (n_y×n_y)
  Gaussian prior_state;     ///< prior on x_c(0)
  Gaussian prior_constants; ///< prior on x_b
};

class Model {
 public:
  virtual ~Model() = default;

  /// Short identifier: the registered type's name ("radar_2d", "linear";
  /// docs/DESIGN.md §3, "Adding a model"), the checkpoint's model tag.
  virtual std::string name() const = 0;

  /// Discrete process model x_c(k+1) = f(x_c(k), x_b, u_k, dt); fills the
  /// Jacobians J_f_xc (n_c×n_c) and J_f_xb (n_c×n_b) when non-null.
  virtual Eigen::VectorXd f(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                            const Eigen::VectorXd& u, double dt,
                            Eigen::MatrixXd* J_f_xc = nullptr,
                            Eigen::MatrixXd* J_f_xb = nullptr) const = 0;

  /// Measurement model of the default channel, y = h(x_c, x_b); fills
  /// J_h_xc (n_y×n_c) and J_h_xb (n_y×n_b) when non-null.
  virtual Eigen::VectorXd h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                            Eigen::MatrixXd* J_h_xc = nullptr,
                            Eigen::MatrixXd* J_h_xb = nullptr) const = 0;
  /// Measurement model of channel `channel` (dimension channel(c).dim()).
  /// Default: channel 0 is h() above; models with several channels override.
  virtual Eigen::VectorXd h(int channel, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                            Eigen::MatrixXd* J_h_xc = nullptr, Eigen::MatrixXd* J_h_xb = nullptr) const;
  /// h(channel, ...) written into `out` (resized to the channel's
  /// dimension): the same numbers without a fresh vector per call, which
  /// the solvers' inner loops use. Default: out = h(channel, ...). A model
  /// evaluated millions of times per run (one range per call) overrides
  /// this and lets h() call it.
  virtual void hInto(int channel, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::VectorXd& out,
                     Eigen::MatrixXd* J_h_xc = nullptr, Eigen::MatrixXd* J_h_xb = nullptr) const;
  /// h of a measurement on `channel` that carries `regressors`
  /// (Measurement::regressors): hInto on a channel that reads none,
  /// hRegressedInto on one that does. InvalidArgument naming the channel
  /// when their number is not the channel's. Every estimator calls this.
  void hWith(int c, const Eigen::VectorXd& regressors, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
             Eigen::VectorXd& out, Eigen::MatrixXd* J_h_xc = nullptr, Eigen::MatrixXd* J_h_xb = nullptr) const {
    if (regressors.size() != channel(c).regressors) throwRegressors(c, regressors.size());
    if (regressors.size() == 0) hInto(c, xc, xb, out, J_h_xc, J_h_xb);
    else hRegressedInto(c, regressors, xc, xb, out, J_h_xc, J_h_xb);
  }
  /// hWith into a fresh vector (tests, reports: off the solvers' loops).
  Eigen::VectorXd hWith(int c, const Eigen::VectorXd& regressors, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                        Eigen::MatrixXd* J_h_xc = nullptr, Eigen::MatrixXd* J_h_xb = nullptr) const {
    Eigen::VectorXd out;
    hWith(c, regressors, xc, xb, out, J_h_xc, J_h_xb);
    return out;
  }
  /// h of a channel with MeasurementChannel::regressors > 0 (a model with
  /// such a channel overrides it; the default throws, naming the channel).
  virtual void hRegressedInto(int channel, const Eigen::VectorXd& regressors, const Eigen::VectorXd& xc,
                              const Eigen::VectorXd& xb, Eigen::VectorXd& out, Eigen::MatrixXd* J_h_xc,
                              Eigen::MatrixXd* J_h_xb) const;

  /// The measurement channels (at least one; channel 0 has n_y components).
  int numChannels() const { return static_cast<int>(channels_.size()); }
  /// Channel c; InvalidArgument naming the count if there is none (inline:
  /// every linearization of a measurement asks for its channel).
  const MeasurementChannel& channel(int c) const {
    if (c < 0 || c >= numChannels()) throwNoChannel(c);
    return channels_[static_cast<std::size_t>(c)];
  }
  /// The channel called `name`; InvalidArgument naming the known ones otherwise.
  int channelIndex(const std::string& name) const;
  /// R of channel c as a whitening noise model (factored once).
  const GaussianNoise& channelNoiseModel(int c) const;
  /// Sets the robust loss and the EKF gate of channel c (before any
  /// estimator uses the model).
  void setChannelLoss(int c, const RobustLoss& loss, double ekf_gate);
  /// Components of the stacked state [x_c; x_b] that are angles.
  const std::vector<int>& angleStates() const { return angle_states_; }
  /// Rotation blocks of the stacked state [x_c; x_b] (docs/DESIGN.md §12):
  /// the first index of each three components that hold a rotation vector φ
  /// (R = Exp(φ)). Every estimator moves them by R ⊕ δ = R·Exp(δ) and
  /// compares them by ⊖ (core/rotation_blocks.h); the model's Jacobians are
  /// with respect to that body-frame tangent δ, its covariances of δ. Empty
  /// for a model of vectors and angles only (every model before #37).
  const std::vector<int>& rotationBlocks() const { return rotation_blocks_; }
  /// The rotation blocks in x_c (constants false) or x_b (true), indexed
  /// within that vector.
  std::vector<int> rotationBlocksIn(bool constants) const;
  /// The stacked state with its angle components wrapped to (−π, π] and its
  /// rotation vectors to |φ| ≤ π.
  Eigen::VectorXd wrapStacked(Eigen::VectorXd z) const;

  /// Process noise covariance of a step of length dt. Default: Q·dt/T (a
  /// white-noise-driven state), which is Q itself at the nominal step.
  virtual Eigen::MatrixXd processNoise(double dt) const;
  /// Process noise of a step under input u (odometry: noise grows with the
  /// distance and the turn). Default: processNoise(dt). A model that
  /// overrides it returns true from processNoiseDependsOnInput().
  virtual Eigen::MatrixXd processNoiseOf(double dt, const Eigen::VectorXd& u) const;
  virtual bool processNoiseDependsOnInput() const { return false; }
  /// > 1: a step's input packs up to this many raw readings, each with its
  /// duration (packed_inputs.h: an INS whose states are not at every IMU
  /// sample); a dataset packs its raw input rows so, with a step ending at
  /// every measurement. 1 (default): one input row per step.
  virtual int readingsPerStep() const { return 1; }

  /// True when f is affine in (x_c, x_b) for every u and dt and x_c has no
  /// rotation block: a process factor's linearization is then exact
  /// everywhere, and the smoothers skip its linearization check (the
  /// residual wrap of an angle state moves nothing below |r| = π).
  /// Default false (always safe).
  virtual bool processIsAffine() const { return false; }
  /// The same for channel c's h (a robust loss still makes its factor's
  /// weight move: those are checked whatever this says). Default false.
  virtual bool measurementIsAffine(int /*channel*/) const { return false; }

  const ModelDims& dims() const { return dims_; }
  const ModelNames& names() const { return names_; }
  const ModelNoise& noise() const { return noise_; }
  double nominalStep() const { return noise_.T; }
  /// R of the default channel (channel 0).
  const Eigen::MatrixXd& measurementNoise() const { return channels_.front().R; }
  /// R as a whitening noise model, factored once per model.
  const GaussianNoise& measurementNoiseModel() const { return channel_noise_.front(); }
  /// Q(dt) as a noise model, factored once per distinct dt among the last
  /// few asked for (time stamps k·T differenced give a handful of dt values
  /// that differ in the last bits) and shared; processNoise must be a pure
  /// function of dt. The error if Q(dt) is not positive definite names
  /// `step` (the message is built only then: this runs once per step).
  GaussianNoise processNoiseModel(double dt, std::int64_t step) const;
  const Gaussian& priorState() const { return noise_.prior_state; }
  const Gaussian& priorConstants() const { return noise_.prior_constants; }

  /// Fixed points its measurements refer to (beacons), in the world frame,
  /// for plan-view figures; none by default.
  virtual std::vector<Eigen::Vector2d> landmarks() const { return {}; }
  /// Points carried by the body at state x_c (sensors at lever arms), in the
  /// world frame, for plan-view figures; none by default.
  virtual std::vector<Eigen::Vector2d> bodyPoints(const Eigen::VectorXd& /*xc*/) const { return {}; }
  /// Their names (one per point), e.g. "tag 0".
  virtual std::vector<std::string> bodyPointNames() const { return {}; }
  /// A model whose positions live in a frame anchored on the Earth maps a
  /// WGS-84 point (latitude, longitude in rad, ellipsoidal height in m) into
  /// it: the GNSS fixes of a log become its measurements. None by default.
  virtual std::optional<Eigen::Vector3d> localPosition(double /*lat*/, double /*lon*/, double /*height*/) const {
    return std::nullopt;
  }

  /// A calibration reference of the constants, for judging estimates (no
  /// estimator reads it): the columns of the reference file this model
  /// understands (none by default), and the constants those rows imply
  /// along the true trajectory `truth` (full x_c rows; NaN for a constant
  /// without a reference). Throws InputError naming the row at fault.
  virtual std::vector<std::string> referenceColumns() const { return {}; }
  virtual Eigen::VectorXd referenceConstants(const Eigen::MatrixXd& /*rows*/, const Truth& /*truth*/) const {
    return Eigen::VectorXd::Constant(dims().nb, std::numeric_limits<double>::quiet_NaN());
  }
  /// Estimated constants (x_b's mean and covariance) in the terms
  /// referenceConstants gives them along `truth`: by default x_b itself.
  virtual Gaussian comparableConstants(const Gaussian& xb, const Truth& /*truth*/) const { return xb; }

  /// All state names in the stacked order [x_c; x_b].
  std::vector<std::string> stackedStateNames() const;

  /// What a user reads of an estimate (`estimates-<method>.csv`'s columns,
  /// each with an sd_ column): by default the stacked state itself. A model
  /// whose states are not the quantities its users judge (an INS: the
  /// antenna's latitude and longitude, the vehicle's Euler angles in
  /// degrees) names its own, and maps a stacked mean and covariance to
  /// their values and standard deviations (first order).
  virtual std::vector<std::string> reportNames() const { return stackedStateNames(); }
  virtual void report(const Eigen::VectorXd& mean, const Eigen::MatrixXd& covariance, Eigen::VectorXd& value,
                      Eigen::VectorXd& sd) const;

 protected:
  /// Validates every dimension, name and covariance; throws InvalidArgument
  /// or NumericalError naming the offending field.
  Model(ModelDims dims, ModelNames names, ModelNoise noise);
  /// Replaces the default channel by these (a model with several sensors);
  /// channel 0 must have n_y components. Validates names and covariances.
  void setChannels(std::vector<MeasurementChannel> channels);
  /// Marks components of the stacked state [x_c; x_b] as angles.
  void setAngleStates(std::vector<int> stacked_components);
  /// Marks rotation blocks (their first stacked components); InvalidArgument
  /// for a block that does not fit in x_c or in x_b, or overlaps another
  /// block or an angle.
  void setRotationBlocks(std::vector<int> first_components);

 private:
  [[noreturn]] void throwNoChannel(int c) const;
  [[noreturn]] void throwRegressors(int c, Eigen::Index given) const;
  std::vector<MeasurementChannel> channels_;
  std::vector<GaussianNoise> channel_noise_;
  std::vector<int> angle_states_;
  std::vector<int> rotation_blocks_;
  ModelDims dims_;
  ModelNames names_;
  ModelNoise noise_;
  struct NoiseCache;
  std::shared_ptr<NoiseCache> q_cache_;  // shared by copies (same parameters); thread-safe
};

/// Result of comparing a model's analytic Jacobians with central differences.
struct JacobianCheck {
  double max_abs_error = 0.0;  ///< worst |analytic − numeric| over all entries
  double max_rel_error = 0.0;  ///< same, relative to max(1, |numeric|)
  std::string worst;           ///< e.g. "J_h_xb(0,1): analytic 0.5, numeric 0.49"
  bool ok(double tol) const { return max_rel_error <= tol; }
};

/// Compares J_f_xc, J_f_xb, J_h_xc and J_h_xb at one point with central
/// differences of step `eps` (scaled by max(1, |x_i|)).
JacobianCheck checkJacobians(const Model& model, const Eigen::VectorXd& xc,
                             const Eigen::VectorXd& xb, const Eigen::VectorXd& u, double dt,
                             double eps = 1e-6);

}  // namespace gssm
