#include "lib/io/history_writer.hpp"

#include <cstdio>
#include <set>
#include <stdexcept>

namespace shelldyn {
const std::vector<std::string>& history_standard_columns() {
  static const std::vector<std::string> cols = {
      "step", "t",  "dt", "kinetic", "strain", "external_work", "total",           "rel_drift",     "Lx",
      "Ly",   "Lz", "Jx", "Jy",      "Jz",     "nonlinear_iters", "linear_setups", "wall_s"};
  return cols;
}

HistoryWriter::HistoryWriter(const std::string& path, std::vector<std::string> extra_columns,
                             std::vector<std::string> monitor_columns)
    : path_(path), num_extra_(extra_columns.size()), num_monitors_(monitor_columns.size()) {
  set_columns(extra_columns, monitor_columns);
  file_ = std::make_unique<AppendFile>(path, header());
}

HistoryWriter::HistoryWriter(const std::string& path, std::vector<std::string> extra_columns,
                             std::vector<std::string> monitor_columns, long long keep_bytes)
    : path_(path), num_extra_(extra_columns.size()), num_monitors_(monitor_columns.size()) {
  set_columns(extra_columns, monitor_columns);
  file_ = std::make_unique<AppendFile>(path, header(), keep_bytes);
}

std::string HistoryWriter::header() const {
  std::string h;
  for (size_t k = 0; k < columns_.size(); ++k) h += (k ? "," : "") + columns_[k];
  return h;
}

long long HistoryWriter::bytes() const { return file_->bytes(); }

void HistoryWriter::sync() { file_->sync(); }

void HistoryWriter::set_columns(const std::vector<std::string>& extra, const std::vector<std::string>& monitors) {
  columns_ = history_standard_columns();
  columns_.insert(columns_.end(), extra.begin(), extra.end());
  columns_.insert(columns_.end(), monitors.begin(), monitors.end());
  check_columns();
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
  file_->append(line);
}

}  // namespace shelldyn
