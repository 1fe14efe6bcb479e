#pragma once
// The output files of one streaming run, written as the run goes (a
// RunRecorder): estimates-<method>.csv (t, what the model reports of each
// estimate and its standard deviations: Model::report) and, when the run takes checkpoints, run-<method>.bin with
// what the metrics need exactly (each row's full covariance, each update's
// latency and NIS). A checkpoint then stores only the two files' lengths:
// its size does not grow with the run, and resuming cuts the files there
// and reads the records back (docs/DESIGN.md §7).
#include <memory>
#include <string>

#include "gssm/analysis/offline.h"
#include "gssm/io/append_file.h"
#include "gssm/io/csv.h"

namespace gssm::io {

class RunFiles final : public RunRecorder {
 public:
  /// The files of `method`'s run in `dir`; none is touched until the first
  /// record (created then) or resume() (continued).
  RunFiles(const std::string& dir, const Model& model, Method method, bool records);

  void row(const EstimateRow& row) override;
  void update(double seconds, std::optional<double> nis) override;
  std::string mark() override;
  void resume(const std::string& mark, OfflineRun& run) override;
  /// Writes what is buffered; throws InputError naming a file that failed.
  void finish();

  static std::string estimatesName(Method method);  ///< "estimates-fixed-lag.csv"
  static std::string recordsName(Method method);    ///< "run-fixed-lag.bin"

 private:
  void open();
  std::string estimates_path_, records_path_;
  std::vector<std::string> header_;
  bool records_;
  const Model& model_;
  Eigen::VectorXd value_, sd_;  // a row's report
  std::unique_ptr<CsvWriter> csv_;
  std::unique_ptr<AppendFile> bin_;  // the records (when records_)
  std::vector<double> line_;
};

}  // namespace gssm::io
