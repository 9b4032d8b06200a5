#include "lib/io/history_writer.hpp"
#include "lib/io/result_folder.hpp"

#include <fcntl.h>

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
  record_output(path);  // the result folder's manifest (lib/io/result_folder.hpp)
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_APPEND | O_CLOEXEC, 0644);
  if (fd_ < 0) throw std::runtime_error(path + ": cannot create history file: " + std::strerror(errno));
  std::string header;
  for (size_t k = 0; k < columns_.size(); ++k) header += (k ? "," : "") + columns_[k];
  write_whole(header + "\n");
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
  fd_ = ::open(path.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
  if (fd_ < 0) throw std::runtime_error(path + ": cannot append to the history file: " + std::strerror(errno));
  bytes_ = keep_bytes;
}

long long HistoryWriter::bytes() const { return fd_ >= 0 ? bytes_ : 0; }

void HistoryWriter::sync() {
  if (fd_ >= 0 && ::fsync(fd_) != 0) throw std::runtime_error(path_ + ": cannot write history.csv: " + write_error_reason(errno));
}

// One write(2) of the whole text (a short write, e.g. on a full disk, is cut back: no half row stays).
void HistoryWriter::write_whole(const std::string& text) {
  if (fd_ < 0) throw std::runtime_error(path_ + ": closed after an earlier write error");
  ssize_t n = ::write(fd_, text.data(), text.size());
  while (n < 0 && errno == EINTR) n = ::write(fd_, text.data(), text.size());
  if (n == static_cast<ssize_t>(text.size())) {
    bytes_ += n;
    return;
  }
  const int err = n < 0 ? errno : ENOSPC;
  if (n > 0 && ftruncate(fd_, static_cast<off_t>(bytes_)) != 0) {
    // if even this fails, the write error below is still the one to report
  }
  ::close(fd_);
  fd_ = -1;
  throw std::runtime_error(path_ + ": cannot write history.csv: " + write_error_reason(err));
}

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
  if (fd_ >= 0) ::close(fd_);
}

void HistoryWriter::write(const HistoryRow& r) {
  if (r.extra.size() != num_extra_ || r.monitors.size() != num_monitors_)
    throw std::invalid_argument("history.csv: row has " + std::to_string(r.extra.size()) + " extra and " +
                                std::to_string(r.monitors.size()) + " monitor values, header expects " +
                                std::to_string(num_extra_) + " and " + std::to_string(num_monitors_));
  std::string line = std::to_string(r.step);
  char b[40];
  auto add = [&](double v) {
    std::snprintf(b, sizeof b, ",%.17g", v);
    line += b;
  };
  for (double v : {r.t, r.dt, r.kinetic, r.strain, r.external_work, r.total, r.rel_drift, r.L.x(), r.L.y(), r.L.z(), r.J.x(),
                   r.J.y(), r.J.z()})
    add(v);
  line += "," + std::to_string(r.nonlinear_iters) + "," + std::to_string(r.linear_setups);
  add(r.wall_s);
  for (double v : r.extra) add(v);
  for (double v : r.monitors) add(v);
  line += '\n';
  write_whole(line);
}

}  // namespace shelldyn
