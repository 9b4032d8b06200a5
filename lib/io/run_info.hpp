// run.json: makes a result folder explain itself (architecture.md §5) — the resolved case settings,
// the software versions, the run status and a summary of key numbers.
//
// The document is built with nlohmann-json (Debian's nlohmann-json3-dev): strings are escaped per
// RFC 8259 (invalid UTF-8 replaced by U+FFFD), numbers in the shortest form that reads back exactly,
// non-finite numbers as null (JSON has no NaN/inf). Files are replaced atomically (temporary + fsync +
// rename); an error names the file and its cause ("the disk is full", "read-only", ...) and removes
// the temporary.
#pragma once

#include "lib/io/case_file.hpp"

#include <string>
#include <utility>
#include <vector>

namespace shelldyn {

// Version of this library (the SHELLDYN_VERSION compile definition of shelldyn_core).
std::string shelldyn_version();
// The git commit this build was made from ("-dirty" appended for local changes), "" outside a checkout.
std::string shelldyn_git_commit();
// "3.4.0": from Eigen's version macros.
std::string eigen_version();

// Ordered key/value pairs with JSON scalar values. Keys keep insertion order; setting an existing
// key replaces its value in place.
class JsonFields {
 public:
  void set(const std::string& key, const std::string& value);
  void set(const std::string& key, const char* value) { set(key, std::string(value)); }
  void set(const std::string& key, double value);
  void set(const std::string& key, int value) { set(key, static_cast<long long>(value)); }
  void set(const std::string& key, long value) { set(key, static_cast<long long>(value)); }
  void set(const std::string& key, long long value);
  void set(const std::string& key, bool value);
  // Each entry is (key, already-encoded JSON value).
  const std::vector<std::pair<std::string, std::string>>& entries() const { return entries_; }
  bool empty() const { return entries_.empty(); }

 private:
  void set_encoded(const std::string& key, std::string json);
  std::vector<std::pair<std::string, std::string>> entries_;
};

struct RunInfo {
  // "complete", "incomplete: <reason>" or "checked" (validated by `shelldyn check`, not run).
  std::string status;
  std::string command;           // the command line, for reproduction
  std::string sundials_version;  // passed in by the caller (SUNDIALS lives in integrators/); may be empty
  JsonFields discretization;     // e.g. nodes, elements, dofs, constrained_dofs, total_mass
  JsonFields summary;            // e.g. steps, final energy, drift, wall time
  JsonFields overrides;          // command-line flags that changed the case ("command_line_overrides")
  JsonFields checkpoint;         // the last checkpoint written (file, t, step), if any
  // Where the run's integrator came from ("built-in", a plugin path, ...; "integrator_origin") and the plugins
  // loaded (path, version, hash, integrators; "plugins", the run's own first). Empty: not written.
  std::string integrator_origin;
  std::vector<JsonFields> plugins;
};

// Encodes a string as a JSON string literal (with quotes).
std::string json_quote(const std::string& s);
// Encodes a number in its shortest round-trip form; NaN and infinities become null.
std::string json_number(double v);

// The whole document as text (pretty-printed, 2-space indentation).
std::string run_json(const CaseSpec& spec, const RunInfo& info);
// Writes run_json() to `path` via a temporary file and a rename (a reader never sees half a file).
// Throws std::runtime_error on I/O errors ("PATH: cannot write run.json: the disk is full ...").
void write_run_json(const std::string& path, const CaseSpec& spec, const RunInfo& info);

// The same for any text file; `what` names it in errors.
void write_text_atomically(const std::string& path, const std::string& text, const std::string& what);

// Room for the last word on a full disk (docs/architecture.md "Checkpoints and resume"): a run keeps
// `path` (DIR/run.json.reserve) allocated while it runs and deletes it right before writing its final
// status, so that when the run's own outputs fill the disk, run.json can still say why the run ended
// instead of staying "incomplete: running". Best effort: if the space cannot be allocated there is no
// reserve (and no error). The destructor deletes the file too.
class DiskReserve {
 public:
  DiskReserve() = default;
  DiskReserve(const std::string& path, long long bytes);
  ~DiskReserve() { release(); }
  DiskReserve(const DiskReserve&) = delete;
  DiskReserve& operator=(const DiskReserve&) = delete;
  void release();
  bool held() const { return !path_.empty(); }

 private:
  std::string path_;
};

}  // namespace shelldyn
