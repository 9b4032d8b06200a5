// Result folders as transactions (docs/guide/result-folders.md).
//
// A result folder is written by one command at a time. The machinery here is shared by every command
// that writes one (run, resume, check, static, modes, the benchmark apps, the runs of compare and study):
//   lock      DIR/.shelldyn.lock, an exclusive flock(2) held while the command writes. The file holds one
//             line naming the holder (pid, host, start time, command); it is removed when the lock is
//             released. A second command into the same folder is refused with one line naming the holder.
//             A lock file whose holder no longer holds the lock (the process was killed: the kernel drops
//             flock locks of dead processes, the file stays) is *stale*: it is reported; `resume`,
//             `--overwrite` and the runs of compare/study take it over with a one-line note, every other
//             command refuses it (remove DIR/.shelldyn.lock after checking the folder to clear it).
//   manifest  DIR/.shelldyn-files: the path (relative to DIR) of every file shelldyn wrote there, one per
//             line, each line appended with one write(2). `--overwrite` removes exactly those (plus the
//             fixed output names of older versions), only if they are regular files, and never through a
//             symbolic link (every path component is opened with O_NOFOLLOW).
//   status    run.json "status" always says what happened; a resume that fails before it could run keeps
//             the folder's earlier status and records the failure as "resume_failed" (record_failed_resume).
//   inputs    require_regular_file: input files must be regular files (a FIFO would block forever).
//   memory    check_memory_estimate: refuse a model whose estimated memory exceeds what is available
//             (or the --max-memory limit) before allocating it.
#pragma once

#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace shelldyn {

// Another process writes into the folder (or left it locked): one line, names the holder and what to do.
class FolderBusy : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline const char* lock_file_name() { return ".shelldyn.lock"; }
inline const char* manifest_file_name() { return ".shelldyn-files"; }

// What to do with a stale lock (its holder died without releasing it).
enum class StaleLock {
  refuse,    // FolderBusy: "left locked by ... (killed?); resume it, --overwrite it, or remove DIR/.shelldyn.lock"
  take_over  // one "note: ..." line on `note` (if not null), then the lock is taken
};

// Scoped exclusive lock of a result folder (created if missing). Re-entrant within one process: a
// command that holds the folder (hold_result_folder) can run code that locks it again. Throws FolderBusy
// if another process holds it or it is stale and `stale` is refuse; std::runtime_error on I/O errors.
class FolderLock {
 public:
  FolderLock() = default;
  FolderLock(const std::string& dir, StaleLock stale, std::ostream* note);
  ~FolderLock();
  FolderLock(FolderLock&& o) noexcept : key_(std::move(o.key_)) { o.key_.clear(); }
  FolderLock& operator=(FolderLock&& o) noexcept;
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;
  bool held() const { return !key_.empty(); }

 private:
  std::string key_;
};

// Locks `dir` until the process ends (the CLI commands: from the folder check to the last output). The
// lock is released (and its file removed) at normal exit; a killed process leaves a stale lock.
void hold_result_folder(const std::string& dir, StaleLock stale, std::ostream* note);

// True if this process holds `dir`.
bool holds_result_folder(const std::string& dir);

// Records `path` in the manifest of the held result folder that contains it (no-op outside held folders,
// and for paths already recorded). Never throws: a manifest that cannot be appended to only makes a later
// --overwrite leave that file in place.
void record_output(const std::string& path) noexcept;

// --overwrite: removes the regular files of `dir` listed in its manifest and those of `legacy_names`
// (top-level names of earlier versions' outputs; plus fields/step_*.vtu if the folder has no manifest), never
// following symbolic links, then the manifest itself. Returns the paths removed (relative to dir).
std::vector<std::string> remove_recorded_outputs(const std::string& dir, const std::vector<std::string>& legacy_names);

// `shelldyn resume DIR`: refuses a DIR that is not a folder (explain_missing_checkpoint), locks it until the
// process ends (a stale lock of the killed run is taken over with a note) and returns its run.json status.
std::string begin_resume(const std::string& dir);

// run.json "status" of `dir` ("" if there is no readable run.json).
std::string read_run_status(const std::string& dir);

// A resume of `dir` failed with `reason`: run.json keeps (or gets back) `previous_status` — the folder's
// contents are still that run's — and records "resume_failed": reason. Best effort (never throws).
void record_failed_resume(const std::string& dir, const std::string& previous_status, const std::string& reason) noexcept;

// The command failed with `reason` (called by the CLI's error handler): every folder this process holds whose
// run.json still says "incomplete: running" — the command failed before the run could record why — gets
// "incomplete: <reason>". Best effort (never throws).
void record_failure(const std::string& reason) noexcept;

// Why DIR has no checkpoint.cbor, as one line for `shelldyn resume` (the run completed, never wrote one, ...).
std::string explain_missing_checkpoint(const std::string& dir);

// Throws std::runtime_error "PATH: is a FIFO/folder/..., not a regular file ..." unless `path` (after
// following symbolic links) is a regular file. `what` names the input ("case file", "mesh file", ...).
// A missing file is not an error here (the caller's open reports it).
void require_regular_file(const std::string& path, const std::string& what);

// --- memory -----------------------------------------------------------------------------------------------
// Bytes this machine can give a process now: the smaller of MemAvailable (/proc/meminfo) and the cgroup
// limit less its usage; 0 if unknown.
long long available_memory_bytes();
// The limit set by --max-memory (0: none, the available memory is the limit).
void set_memory_limit(long long bytes);
long long memory_limit();
// Parses "4G", "512M", "2e9", "800k" (powers of 1024 for k/M/G/T). Throws std::invalid_argument with an example.
long long parse_memory_size(const std::string& text);
// "1.5 GiB"
std::string memory_text(double bytes);
// Refuses (std::runtime_error, one line starting with `where`) a model of `nodes` nodes and `elements` quad9
// elements whose estimated memory exceeds the limit (--max-memory, else the available memory). `where` is the
// case line of the mesh (FILE:LINE: mesh), `fix` how to make it smaller.
void check_memory_estimate(long long nodes, long long elements, const std::string& where, const std::string& fix);
// The estimate itself (bytes): stiffness, mass and tangent matrices, their sparse factorization and the
// state vectors of the integrators (docs/guide/result-folders.md "Sizes that do not fit").
double estimate_model_bytes(long long nodes, long long elements);

}  // namespace shelldyn
