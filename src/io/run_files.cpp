#include "gssm/io/run_files.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/byte_stream.h"
#include "gssm/core/error.h"

namespace gssm::io {

namespace fs = std::filesystem;

namespace {
constexpr const char* kMarkTag = "gssm run files v1";
}  // namespace

std::string RunFiles::estimatesName(Method method) { return std::string("estimates-") + methodName(method) + ".csv"; }
std::string RunFiles::recordsName(Method method) { return std::string("run-") + methodName(method) + ".bin"; }

RunFiles::RunFiles(const std::string& dir, const Model& model, Method method, bool records)
    : estimates_path_((fs::path(dir) / estimatesName(method)).string()),
      records_path_((fs::path(dir) / recordsName(method)).string()),
      records_(records),
      model_(model) {
  header_.push_back("t");
  const auto names = model.reportNames();
  for (const auto& n : names) header_.push_back(n);
  for (const auto& n : names) header_.push_back("sd_" + n);
}

void RunFiles::open() {
  csv_ = std::make_unique<CsvWriter>(estimates_path_, header_);
  if (records_) bin_ = std::make_unique<AppendFile>(records_path_);
}

void RunFiles::row(const EstimateRow& r) {
  if (!csv_) open();
  model_.report(r.mean, r.covariance, value_, sd_);
  line_.assign(1, r.t);
  line_.insert(line_.end(), value_.data(), value_.data() + value_.size());
  line_.insert(line_.end(), sd_.data(), sd_.data() + sd_.size());
  csv_->row(line_);
  if (!records_) return;
  internal::ByteWriter w;
  w.boolean(true);  // a row
  w.f64(r.t);
  w.vec(r.mean);
  w.mat(r.covariance);
  bin_->buffer() += w.bytes();
  bin_->maybeWrite();
}

void RunFiles::update(double seconds, std::optional<double> nis) {
  if (!records_) return;
  if (!csv_) open();
  internal::ByteWriter w;
  w.boolean(false);  // an update
  w.f64(seconds);
  w.boolean(nis.has_value());
  if (nis) w.f64(*nis);
  bin_->buffer() += w.bytes();
  bin_->maybeWrite();
}

std::string RunFiles::mark() {
  if (!records_) throw InvalidArgument("RunFiles: a mark needs the records file (construct with records = true)");
  if (!csv_) open();
  const std::uint64_t csv_length = csv_->flush();
  const std::uint64_t bin_length = bin_->flush();
  internal::ByteWriter w;
  w.str(kMarkTag);
  w.u64(csv_length);
  w.u64(bin_length);
  return w.bytes();
}

void RunFiles::resume(const std::string& mark, OfflineRun& run) {
  internal::ByteReader m(mark, "checkpoint (output files)");
  if (m.str("output files tag") != kMarkTag) m.fail("not a mark of gssm-process's output files");
  const std::uint64_t csv_length = m.u64("estimates length"), bin_length = m.u64("records length");
  if (!m.atEnd()) m.fail("unexpected bytes after the output files' lengths");
  // The records up to the mark, read back exactly.
  std::string bytes;
  {
    std::ifstream in(records_path_, std::ios::binary);
    if (!in) throw CheckpointError(records_path_ + ": cannot resume: the run's records file is missing");
    bytes.resize(bin_length);
    in.read(bytes.data(), static_cast<std::streamsize>(bin_length));
    if (static_cast<std::uint64_t>(in.gcount()) != bin_length)
      throw CheckpointError(records_path_ + ": cannot resume: it has fewer than the " + std::to_string(bin_length) +
                            " bytes the checkpoint recorded");
  }
  internal::ByteReader r(bytes, records_path_);
  run.rows.clear();
  run.update_seconds.clear();
  run.nis.clear();
  while (!r.atEnd()) {
    if (r.boolean("record kind")) {
      EstimateRow row;
      row.t = r.f64("row time");
      row.mean = r.vec("row mean");
      row.covariance = r.mat("row covariance");
      run.rows.push_back(std::move(row));
    } else {
      run.update_seconds.push_back(r.f64("latency"));
      if (r.boolean("has NIS")) run.nis.push_back(r.f64("NIS", true));
    }
  }
  // Continue both files at the mark.
  csv_ = std::make_unique<CsvWriter>(estimates_path_, csv_length);
  bin_ = std::make_unique<AppendFile>(records_path_, bin_length);
}

void RunFiles::finish() {
  if (!csv_) open();  // a run with no rows still writes its header
  csv_->flush();
  if (bin_) bin_->flush();
}

}  // namespace gssm::io
