// Checkpoint files of dynamic runs (docs/architecture.md "Checkpoints and resume").
//
// A checkpoint holds everything needed to continue a run as if it had never stopped:
//   state        t, u, v, a, pdot and the director chart of every node (lib/model/state.hpp)
//   integrator   the integrator's own data (Integrator::save: W_ext, history vectors, solver state)
//   numbers      the run driver's counters and reference quantities (output index, history.csv
//                size, summary extrema, ...), and the options needed to rebuild the run
//   texts        the case file's text and where it came from, the command line, ...
//   vectors      further named vectors of the driver (e.g. the .pvd times)
// Format: CBOR (RFC 8949) written with nlohmann-json; every double is stored bit for bit (vectors
// as raw little-endian byte strings), so a resumed run starts from exactly the saved numbers. Files
// are replaced atomically (temporary + fsync + rename): a run killed while writing keeps the previous
// checkpoint. read_checkpoint() rejects files of another format or version with one line.
//
// Integrity (docs/guide/result-folders.md "Checkpoints"): since version 2 the file is a small CBOR map
// {format, version, shelldyn, case_hash, checksum, body}: `body` is the CBOR document above as a byte
// string, `shelldyn` the version of the binary that wrote it, `case_hash` the hash of the case text the run
// started from, and `checksum` the 64-bit FNV-1a hash of shelldyn, case_hash and body together. FNV-1a
// maps any change of a single byte to a different hash (each step is a bijection of the state), so every
// bit flip is detected; other damage escapes with probability 2^-64. A damaged file is refused with one line.
#pragma once

#include "integrators/integrator.hpp"
#include "lib/model/state.hpp"

#include <Eigen/Core>

#include <map>
#include <ostream>
#include <string>

namespace shelldyn {

struct Checkpoint {
  static constexpr int kVersion = 2;
  State state;
  std::string integrator;  // name of the integrator that saved `integrator_data`
  IntegratorCheckpoint integrator_data;
  std::map<std::string, double> numbers;
  std::map<std::string, std::string> texts;
  std::map<std::string, Eigen::VectorXd> vectors;
  std::string made_by;  // shelldyn version that wrote the file (read_checkpoint; empty for version 1 files)

  double number(const std::string& key) const;                 // throws naming the key if absent
  const std::string& text(const std::string& key) const;       // likewise
  const Eigen::VectorXd& vector(const std::string& key) const;  // likewise
};

// Writes `c` to `path` atomically. Throws std::runtime_error naming the file and the cause.
void write_checkpoint(const std::string& path, const Checkpoint& c);
// Reads a checkpoint. Throws std::runtime_error "PATH: ..." if it is missing, truncated, corrupt or
// of another version.
Checkpoint read_checkpoint(const std::string& path);

// `shelldyn resume`: refuses (std::runtime_error, one line) a checkpoint whose case file was edited since the
// run started (texts case_source/case_text), unless allow_changed_case, and one written by another shelldyn
// version or one of format 1 (no checksum), unless allow_other_version; with the flag, or when the case file is
// gone, one note on `note`.
void check_checkpoint_origin(const Checkpoint& c, const std::string& path, bool allow_changed_case,
                             bool allow_other_version, std::ostream* note);

// FNV-1a 64-bit hash as 16 hex digits (identifies case and mesh files in checkpoints).
std::string content_hash(const std::string& bytes);

}  // namespace shelldyn
