#include "lib/history_writer.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <set>
#include <stdexcept>

namespace shelldyn {
namespace {
std::string write_error_reason(int err) {
  return err == ENOSPC ? std::string("the disk is full (free space and rerun)") : std::string(std::strerror(err));
}
}  // namespace

const std::vector<std::string>& history_standard_columns() {
  static const std::vector<std::string> cols = {
      "step", "t",  "dt", "kinetic", "strain", "external_work", "total",           "rel_drift",     "Lx",
      "Ly",   "Lz", "Jx", "Jy",      "Jz",     "nonlinear_iters", "linear_setups", "wall_s"};
  return cols;
}

HistoryWriter::HistoryWriter(const std::string& path, std::vector<std::string> extra_columns,
                             std::vector<std::string> monitor_columns)
    : path_(path), num_extra_(extra_columns.size()), num_monitors_(monitor_columns.size()) {
  columns_ = history_standard_columns();
  columns_.insert(columns_.end(), extra_columns.begin(), extra_columns.end());
  columns_.insert(columns_.end(), monitor_columns.begin(), monitor_columns.end());
  check_columns();
  file_ = std::fopen(path.c_str(), "w");
  if (!file_) throw std::runtime_error(path + ": cannot create history file: " + std::strerror(errno));
  for (size_t k = 0; k < columns_.size(); ++k) std::fprintf(file_, "%s%s", k ? "," : "", columns_[k].c_str());
  std::fputc('\n', file_);
  if (std::fflush(file_) != 0) throw std::runtime_error(path_ + ": cannot write history.csv: " + write_error_reason(errno));
}

HistoryWriter::HistoryWriter(const std::string& path, std::vector<std::string> extra_columns,
                             std::vector<std::string> monitor_columns, long long keep_bytes)
    : path_(path), num_extra_(extra_columns.size()), num_monitors_(monitor_columns.size()) {
  columns_ = history_standard_columns();
  columns_.insert(columns_.end(), extra_columns.begin(), extra_columns.end());
  columns_.insert(columns_.end(), monitor_columns.begin(), monitor_columns.end());
  check_columns();
  std::string header;
  for (size_t k = 0; k < columns_.size(); ++k) header += (k ? "," : "") + columns_[k];
  std::FILE* in = std::fopen(path.c_str(), "rb");
  if (!in) throw std::runtime_error(path + ": cannot reopen the history file to resume: " + std::strerror(errno));
  std::string first;
  for (int c; (c = std::fgetc(in)) != EOF && c != '\n';) first += static_cast<char>(c);
  std::fseek(in, 0, SEEK_END);
  const long size = std::ftell(in);
  std::fclose(in);
  if (first != header) throw std::runtime_error(path + ": header differs from this run's columns; cannot resume");
  if (size < keep_bytes || keep_bytes < static_cast<long long>(header.size()) + 1)
    throw std::runtime_error(path + ": shorter than at the checkpoint (" + std::to_string(size) + " < " +
                             std::to_string(keep_bytes) + " bytes); cannot resume");
  if (truncate(path.c_str(), static_cast<off_t>(keep_bytes)) != 0)
    throw std::runtime_error(path + ": cannot cut the rows after the checkpoint: " + std::strerror(errno));
  file_ = std::fopen(path.c_str(), "a");
  if (!file_) throw std::runtime_error(path + ": cannot append to the history file: " + std::strerror(errno));
}

long long HistoryWriter::bytes() const { return file_ ? static_cast<long long>(std::ftell(file_)) : 0; }

void HistoryWriter::check_columns() {
  std::set<std::string> seen;
  for (const auto& c : columns_) {
    if (c.empty() || c.find_first_of(",\"\r\n") != std::string::npos)
      throw std::invalid_argument("history.csv: invalid column name '" + c +
                                  "' (must be non-empty, without commas, quotes or line breaks)");
    if (!seen.insert(c).second)
      throw std::invalid_argument("history.csv: column '" + c + "' appears twice (rename the monitor or extra column)");
  }
}

HistoryWriter::~HistoryWriter() {
  if (file_) std::fclose(file_);
}

void HistoryWriter::write(const HistoryRow& r) {
  if (r.extra.size() != num_extra_ || r.monitors.size() != num_monitors_)
    throw std::invalid_argument("history.csv: row has " + std::to_string(r.extra.size()) + " extra and " +
                                std::to_string(r.monitors.size()) + " monitor values, header expects " +
                                std::to_string(num_extra_) + " and " + std::to_string(num_monitors_));
  if (!file_) throw std::runtime_error(path_ + ": closed after an earlier write error");
  const long row_start = std::ftell(file_);
  std::fprintf(file_, "%lld", r.step);
  const double reals[] = {r.t, r.dt, r.kinetic, r.strain, r.external_work, r.total, r.rel_drift,
                          r.L.x(), r.L.y(), r.L.z(), r.J.x(), r.J.y(), r.J.z()};
  for (double v : reals) std::fprintf(file_, ",%.17g", v);
  std::fprintf(file_, ",%lld,%lld,%.17g", r.nonlinear_iters, r.linear_setups, r.wall_s);
  for (double v : r.extra) std::fprintf(file_, ",%.17g", v);
  for (double v : r.monitors) std::fprintf(file_, ",%.17g", v);
  std::fputc('\n', file_);
  if (std::fflush(file_) != 0 || std::ferror(file_)) {
    const int err = errno;
    // No half row: close, then cut the file back to the rows written whole (close first, so that
    // nothing left in the stdio buffer lands after the cut).
    std::fclose(file_);
    file_ = nullptr;
    if (row_start >= 0) {
      const int rc = truncate(path_.c_str(), static_cast<off_t>(row_start));
      (void)rc;  // if even this fails, the write error below is still the one to report
    }
    throw std::runtime_error(path_ + ": cannot write history.csv: " + write_error_reason(err));
  }
}

}  // namespace shelldyn
