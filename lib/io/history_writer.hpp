// history.csv: one row per output step (architecture.md §5), for tools and plots.
//
// Columns, in order: the standard columns of history_standard_columns(), then the caller's extra
// columns (integrator-specific counters), then one column per monitor. Values are written with
// %.17g (round-trip exact); integer counters as integers. Each row is formatted whole and reaches the
// file with one write(2) on an O_APPEND descriptor (docs/guide/result-folders.md "history.csv"): a killed
// run leaves complete rows only, and nothing is buffered in the process. sync() (fsync) is called by the
// run driver before each checkpoint, so that a checkpoint never counts rows a power loss could take back.
#pragma once

#include <Eigen/Core>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "lib/io/append_file.hpp"

namespace shelldyn {

// step,t,dt,kinetic,strain,external_work,total,rel_drift,Lx,Ly,Lz,Jx,Jy,Jz,nonlinear_iters,
// linear_setups,wall_s
const std::vector<std::string>& history_standard_columns();

struct HistoryRow {
  long long step = 0;
  double t = 0, dt = 0;
  double kinetic = 0, strain = 0, external_work = 0, total = 0, rel_drift = 0;
  Eigen::Vector3d L = Eigen::Vector3d::Zero();  // linear momentum (docs/theory.md §5.4)
  Eigen::Vector3d J = Eigen::Vector3d::Zero();  // angular momentum about the origin, director term included
  long long nonlinear_iters = 0, linear_setups = 0;
  double wall_s = 0;
  std::vector<double> extra;     // one per extra column, in order
  std::vector<double> monitors;  // one per monitor column, in order
};

class HistoryWriter {
 public:
  // Creates (truncates) `path` and writes the header. Throws std::runtime_error if the file cannot be
  // opened, std::invalid_argument if a column name is empty, contains ',', '"' or a line break, or
  // repeats another column.
  HistoryWriter(const std::string& path, std::vector<std::string> extra_columns,
                std::vector<std::string> monitor_columns);
  // Resume (checkpoint restart): keeps the first `keep_bytes` bytes of an existing `path` (the rows
  // up to the checkpoint), drops the rest and appends from there. Throws std::runtime_error if the
  // file is shorter or its header differs from these columns.
  HistoryWriter(const std::string& path, std::vector<std::string> extra_columns,
                std::vector<std::string> monitor_columns, long long keep_bytes);
  HistoryWriter(const HistoryWriter&) = delete;
  HistoryWriter& operator=(const HistoryWriter&) = delete;

  // Appends one row and flushes. Throws std::invalid_argument if the numbers of extra or monitor
  // values do not match the header, std::runtime_error on a write error.
  void write(const HistoryRow& row);

  const std::vector<std::string>& columns() const { return columns_; }
  const std::string& path() const { return path_; }
  // Bytes written so far (header included): the resume position of a checkpoint.
  long long bytes() const;
  // fsync(2): the rows written so far are on the disk. Throws std::runtime_error on failure.
  void sync();

 private:
  void set_columns(const std::vector<std::string>& extra, const std::vector<std::string>& monitors);
  void check_columns();
  std::string header() const;
  std::string path_;
  std::unique_ptr<AppendFile> file_;  // one write(2) per row (lib/io/append_file.hpp)
  size_t num_extra_ = 0, num_monitors_ = 0;
  std::vector<std::string> columns_;
};

}  // namespace shelldyn
