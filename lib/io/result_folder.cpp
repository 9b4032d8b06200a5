// Result folders as transactions: see lib/io/result_folder.hpp and docs/guide/result-folders.md.
#include "lib/io/result_folder.hpp"

#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>

namespace shelldyn {
namespace fs = std::filesystem;
namespace {

std::string folder_key(const std::string& dir) {
  std::error_code ec;
  fs::path p = fs::absolute(dir.empty() ? "." : dir, ec);
  const fs::path c = fs::weakly_canonical(p, ec);
  return (ec ? p : c).lexically_normal().string();
}

std::string hostname() {
  char h[256] = {0};
  if (gethostname(h, sizeof h - 1) != 0) return "?";
  return h;
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char b[32];
  std::strftime(b, sizeof b, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return b;
}

std::string process_command() {
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  std::string s((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (char& c : s)
    if (c == '\0' || c == '\n' || c == '\r') c = ' ';
  while (!s.empty() && s.back() == ' ') s.pop_back();
  if (s.size() > 300) s = s.substr(0, 297) + "...";
  return s;
}

// One line: "pid=P host=H start=T command=C".
std::string holder_record() {
  return "pid=" + std::to_string(getpid()) + " host=" + hostname() + " start=" + utc_now() + " command=" + process_command() +
         "\n";
}

std::string read_fd(int fd) {
  std::string s;
  char b[1024];
  off_t off = 0;
  for (ssize_t n; (n = pread(fd, b, sizeof b, off)) > 0 && s.size() < 4096; off += n) s.append(b, static_cast<size_t>(n));
  while (!s.empty() && (s.back() == '\n' || s.back() == '\0')) s.pop_back();
  return s;
}

// "pid 123 on host (since T, `command`)" from a holder record.
std::string describe_holder(const std::string& rec) {
  auto field = [&](const std::string& key) -> std::string {
    const auto p = rec.find(key + "=");
    if (p == std::string::npos) return "?";
    const auto b = p + key.size() + 1;
    const auto e = key == "command" ? std::string::npos : rec.find(' ', b);
    return rec.substr(b, e == std::string::npos ? std::string::npos : e - b);
  };
  if (rec.empty()) return "another process";
  return "pid " + field("pid") + " on " + field("host") + " (since " + field("start") + ": " + field("command") + ")";
}

struct Held {
  int fd = -1;
  int count = 0;
  bool sticky = false;
  std::string dir;                // as given
  std::string lock_path;
  std::set<std::string> recorded;  // manifest entries written by this process
  int manifest_fd = -1;
};

struct Registry {
  std::mutex m;
  std::map<std::string, Held> held;
  ~Registry() {  // normal exit: release the folders still held (hold_result_folder)
    for (auto& [key, h] : held) {
      if (h.manifest_fd >= 0) ::close(h.manifest_fd);
      ::unlink(h.lock_path.c_str());
      ::close(h.fd);
    }
  }
};

Registry& registry() {
  static Registry r;
  return r;
}

void acquire(const std::string& dir, StaleLock stale, std::ostream* note, bool sticky) {
  const std::string key = folder_key(dir);
  Registry& r = registry();
  std::lock_guard<std::mutex> g(r.m);
  if (auto it = r.held.find(key); it != r.held.end()) {
    ++it->second.count;
    it->second.sticky = it->second.sticky || sticky;
    return;
  }
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create output folder '" + dir + "': " + ec.message());
  const std::string path = (fs::path(dir) / lock_file_name()).string();
  for (int attempt = 0; attempt < 20; ++attempt) {
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (fd < 0)
      throw std::runtime_error(path + ": cannot create the folder's lock file: " + std::strerror(errno) +
                               (errno == ELOOP ? " (it is a symbolic link; remove it)" : ""));
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      const std::string rec = read_fd(fd);
      ::close(fd);
      if (err == EWOULDBLOCK)
        throw FolderBusy(dir + ": in use by " + describe_holder(rec) +
                         "; wait for it to finish, or choose another folder with -o");
      throw std::runtime_error(path + ": cannot lock the result folder: " + std::strerror(err));
    }
    // The holder before us may have removed the file between our open and our flock: then we locked a
    // file that no longer has this name. Try again with the current one.
    struct stat a{}, b{};
    if (fstat(fd, &a) != 0 || lstat(path.c_str(), &b) != 0 || a.st_dev != b.st_dev || a.st_ino != b.st_ino) {
      ::close(fd);
      continue;
    }
    const std::string rec = read_fd(fd);
    if (!rec.empty()) {  // stale: its holder ended without releasing (killed); the kernel dropped its flock
      const std::string who = describe_holder(rec);
      if (stale == StaleLock::refuse) {
        ::close(fd);
        // The way to continue depends on what held it: a run (resume), a compare sweep (--resume), a study.
        const std::string how = who.find(" compare ") != std::string::npos
                                    ? "continue it with the same `shelldyn compare` and --resume"
                                : who.find(" study ") != std::string::npos
                                    ? "continue it with the same `shelldyn study` (it keeps the finished runs)"
                                    : "continue it with `shelldyn resume`, replace it with --overwrite";
        throw FolderBusy(dir + ": left locked by " + who + ", which is no longer running (killed?); " + how +
                         ", or remove " + lock_file_name() + " after checking the folder");
      }
      if (note) *note << "note: " << dir << ": taking over the lock of " << who << ", which ended without releasing it" << std::endl;
    }
    const std::string mine = holder_record();
    if (ftruncate(fd, 0) != 0 || pwrite(fd, mine.data(), mine.size(), 0) != static_cast<ssize_t>(mine.size())) {
      const int err = errno;
      ::unlink(path.c_str());
      ::close(fd);
      throw std::runtime_error(path + ": cannot write the folder's lock file: " + std::strerror(err));
    }
    Held h;
    h.fd = fd;
    h.count = 1;
    h.sticky = sticky;
    h.dir = dir;
    h.lock_path = path;
    r.held.emplace(key, std::move(h));
    return;
  }
  throw FolderBusy(dir + ": its lock file keeps changing (several commands starting at once?); retry");
}

void release(const std::string& key) {
  Registry& r = registry();
  std::lock_guard<std::mutex> g(r.m);
  auto it = r.held.find(key);
  if (it == r.held.end()) return;
  if (--it->second.count > 0 || it->second.sticky) return;
  Held& h = it->second;
  if (h.manifest_fd >= 0) ::close(h.manifest_fd);
  ::unlink(h.lock_path.c_str());  // while still locked: a waiter re-checks the name (acquire)
  ::close(h.fd);
  r.held.erase(it);
}

bool safe_relative(const std::string& rel) {
  if (rel.empty() || rel.front() == '/') return false;
  for (const auto& part : fs::path(rel))
    if (part == ".." || part == ".") return false;
  return true;
}

// Removes DIR/rel if it is a regular file, opening every folder on the way with O_NOFOLLOW.
bool remove_regular_nofollow(int dirfd, const std::string& rel) {
  if (!safe_relative(rel)) return false;
  const fs::path p(rel);
  int fd = ::dup(dirfd);
  if (fd < 0) return false;
  std::vector<std::string> parts;
  for (const auto& part : p) parts.push_back(part.string());
  for (size_t k = 0; k + 1 < parts.size(); ++k) {
    const int next = ::openat(fd, parts[k].c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    ::close(fd);
    if (next < 0) return false;  // missing, or a symbolic link: not followed
    fd = next;
  }
  struct stat st{};
  bool removed = false;
  if (fstatat(fd, parts.back().c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0 && S_ISREG(st.st_mode))
    removed = ::unlinkat(fd, parts.back().c_str(), 0) == 0;
  ::close(fd);
  return removed;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

long long g_memory_limit = 0;

}  // namespace

FolderLock::FolderLock(const std::string& dir, StaleLock stale, std::ostream* note) {
  acquire(dir, stale, note, false);
  key_ = folder_key(dir);
}

FolderLock::~FolderLock() {
  if (!key_.empty()) release(key_);
}

FolderLock& FolderLock::operator=(FolderLock&& o) noexcept {
  if (this != &o) {
    if (!key_.empty()) release(key_);
    key_ = std::move(o.key_);
    o.key_.clear();
  }
  return *this;
}

void hold_result_folder(const std::string& dir, StaleLock stale, std::ostream* note) { acquire(dir, stale, note, true); }

bool holds_result_folder(const std::string& dir) {
  Registry& r = registry();
  std::lock_guard<std::mutex> g(r.m);
  return r.held.count(folder_key(dir)) > 0;
}

void record_output(const std::string& path) noexcept {
  try {
    const std::string file = folder_key(path);
    Registry& r = registry();
    std::lock_guard<std::mutex> g(r.m);
    // The innermost held folder that contains the file.
    Held* best = nullptr;
    size_t best_len = 0;
    for (auto& [key, h] : r.held) {
      if (file.size() > key.size() + 1 && file.compare(0, key.size(), key) == 0 && file[key.size()] == '/' &&
          key.size() > best_len) {
        best = &h;
        best_len = key.size();
      }
    }
    if (!best) return;
    const std::string rel = file.substr(best_len + 1);
    if (rel == lock_file_name() || rel == manifest_file_name() || !best->recorded.insert(rel).second) return;
    if (best->manifest_fd < 0) {
      const std::string m = (fs::path(best->dir) / manifest_file_name()).string();
      best->manifest_fd = ::open(m.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC | O_NOFOLLOW, 0644);
      if (best->manifest_fd < 0) return;
    }
    const std::string line = rel + "\n";  // one write(2) of a whole line (O_APPEND): never a torn entry
    const ssize_t n = ::write(best->manifest_fd, line.data(), line.size());
    (void)n;
  } catch (...) {
  }
}

std::vector<std::string> remove_recorded_outputs(const std::string& dir, const std::vector<std::string>& legacy_names) {
  std::vector<std::string> removed;
  const int dirfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dirfd < 0) return removed;
  std::vector<std::string> names;
  const std::string manifest = (fs::path(dir) / manifest_file_name()).string();
  struct stat st{};
  const bool have_manifest = fstatat(dirfd, manifest_file_name(), &st, AT_SYMLINK_NOFOLLOW) == 0 && S_ISREG(st.st_mode);
  if (have_manifest) {
    std::istringstream in(read_text(manifest));
    for (std::string line; std::getline(in, line);)
      if (!line.empty()) names.push_back(line);
  } else {
    // A folder of an earlier version (no manifest): its VTUs, but only in a real fields/ folder.
    const int fd = ::openat(dirfd, "fields", O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (fd >= 0) {
      ::close(fd);
      std::error_code ec;
      for (const auto& e : fs::directory_iterator(fs::path(dir) / "fields", ec)) {
        const std::string n = e.path().filename().string();
        if (n.rfind("step_", 0) == 0 && (e.path().extension() == ".vtu" || e.path().extension() == ".tmp"))
          names.push_back("fields/" + n);
      }
    }
  }
  names.insert(names.end(), legacy_names.begin(), legacy_names.end());
  std::set<std::string> done;
  for (const auto& n : names)
    if (done.insert(n).second && remove_regular_nofollow(dirfd, n)) removed.push_back(n);
  if (have_manifest) {
    // Entries this process already recorded are gone now: forget them, so that they are recorded again.
    Registry& r = registry();
    {
      std::lock_guard<std::mutex> g(r.m);
      if (auto it = r.held.find(folder_key(dir)); it != r.held.end()) {
        it->second.recorded.clear();
        if (it->second.manifest_fd >= 0) ::close(it->second.manifest_fd);
        it->second.manifest_fd = -1;
      }
    }
    ::unlinkat(dirfd, manifest_file_name(), 0);
  }
  ::close(dirfd);
  return removed;
}

std::string begin_resume(const std::string& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw std::runtime_error(explain_missing_checkpoint(dir));
  hold_result_folder(dir, StaleLock::take_over, &std::cerr);
  return read_run_status(dir);
}

std::string read_run_status(const std::string& dir) {
  const std::string text = read_text((fs::path(dir) / "run.json").string());
  if (text.empty()) return {};
  try {
    const auto j = nlohmann::json::parse(text);
    return j.is_object() && j.contains("status") && j["status"].is_string() ? j["status"].get<std::string>() : std::string();
  } catch (...) {
    return {};
  }
}

namespace {
// Sets run.json "status" (and optionally "resume_failed") of `dir` when its status is `only_if` (empty: always).
void patch_run_json(const std::string& dir, const std::string& only_if, const std::string& status,
                    const std::string& resume_failed) {
  const std::string path = (fs::path(dir) / "run.json").string();
  const std::string text = read_text(path);
  if (text.empty()) return;
  auto j = nlohmann::json::parse(text);
  if (!j.is_object()) return;
  const std::string now = j.value("status", std::string());
  if (!only_if.empty() && now != only_if) return;
  if (!status.empty()) j["status"] = status;
  if (!resume_failed.empty()) j["resume_failed"] = resume_failed;
  const std::string out = j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    f << out;
    if (!f) {
      std::remove(tmp.c_str());
      return;
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) std::remove(tmp.c_str());
}
}  // namespace

void record_failed_resume(const std::string& dir, const std::string& previous_status, const std::string& reason) noexcept {
  try {
    // The resume's own "incomplete: running" says nothing true: the folder still holds the run as it was.
    if (!previous_status.empty()) patch_run_json(dir, "incomplete: running", previous_status, "");
    patch_run_json(dir, "", "", reason);
  } catch (...) {
  }
}

void record_failure(const std::string& reason) noexcept {
  try {
    std::vector<std::string> dirs;
    {
      Registry& r = registry();
      std::lock_guard<std::mutex> g(r.m);
      for (const auto& [key, h] : r.held) dirs.push_back(h.dir);
    }
    std::string one = reason;
    for (char& c : one)
      if (c == '\n' || c == '\r') c = ' ';
    for (const auto& d : dirs) patch_run_json(d, "incomplete: running", "incomplete: " + one, "");
  } catch (...) {
  }
}

std::string explain_missing_checkpoint(const std::string& dir) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) return dir + ": no such folder (give the result folder of the run to continue)";
  if (!fs::is_directory(dir, ec)) return dir + ": not a folder (give the result folder of the run to continue)";
  const std::string status = read_run_status(dir);
  if (status.empty())
    return dir + ": not the result folder of a run (no run.json); give the folder that `shelldyn run -o` wrote";
  if (status == "complete")
    return dir + ": the run is complete, nothing to resume; to run further, start a new run with a later --t-end into "
                 "another folder";
  if (status == "checked") return dir + ": written by `shelldyn check`, not by a run; nothing to resume";
  if (status.rfind("incomplete: running", 0) == 0)
    return dir + ": the run was killed before its first checkpoint (written every 60 s of wall time by default, see "
                 "--checkpoint-every); rerun it with --overwrite";
  return dir + ": the run ended (" + status.substr(0, 80) + (status.size() > 80 ? "..." : "") +
         ") without a checkpoint (its integrator writes none, or --checkpoint-every off); rerun it with --overwrite";
}

void require_regular_file(const std::string& path, const std::string& what) {
  struct stat st{};
  if (::stat(path.c_str(), &st) != 0) return;  // missing: the caller's open says so
  if (S_ISREG(st.st_mode)) return;
  const char* kind = S_ISFIFO(st.st_mode)  ? "a FIFO (named pipe)"
                     : S_ISDIR(st.st_mode) ? "a folder"
                     : S_ISCHR(st.st_mode) ? "a character device"
                     : S_ISBLK(st.st_mode) ? "a block device"
                     : S_ISSOCK(st.st_mode) ? "a socket"
                                            : "not a regular file";
  throw std::runtime_error(path + ": is " + kind + ", not a regular file; give the " + what + " itself");
}

// --- memory -------------------------------------------------------------------------------------------------
long long available_memory_bytes() {
  long long avail = 0;
  {
    std::ifstream in("/proc/meminfo");
    std::string key;
    long long kb = 0;
    std::string unit;
    while (in >> key >> kb >> unit)
      if (key == "MemAvailable:") {
        avail = kb * 1024;
        break;
      }
  }
  // cgroup v2 limit of this process (containers, systemd slices, batch jobs).
  const std::string max = read_text("/sys/fs/cgroup/memory.max");
  if (!max.empty() && max.rfind("max", 0) != 0) {
    const long long lim = std::atoll(max.c_str());
    const long long used = std::atoll(read_text("/sys/fs/cgroup/memory.current").c_str());
    if (lim > 0) {
      const long long room = lim > used ? lim - used : 0;
      avail = avail > 0 ? std::min(avail, room) : room;
    }
  }
  return avail;
}

void set_memory_limit(long long bytes) { g_memory_limit = bytes > 0 ? bytes : 0; }
long long memory_limit() { return g_memory_limit; }

long long parse_memory_size(const std::string& text) {
  const std::string how = " (e.g. 4G, 512M, 2e9 bytes)";
  if (text.empty()) throw std::invalid_argument("--max-memory: empty" + how);
  double scale = 1.0;
  std::string num = text;
  const char u = static_cast<char>(std::toupper(static_cast<unsigned char>(text.back())));
  if (u == 'K' || u == 'M' || u == 'G' || u == 'T') {
    scale = u == 'K' ? 1024.0 : u == 'M' ? 1048576.0 : u == 'G' ? 1073741824.0 : 1099511627776.0;
    num.pop_back();
  }
  char* end = nullptr;
  const double x = std::strtod(num.c_str(), &end);
  if (num.empty() || *end != '\0' || !std::isfinite(x) || !(x > 0.0) || x * scale > 1e18)
    throw std::invalid_argument("--max-memory '" + text + "': not a positive size" + how);
  return static_cast<long long>(x * scale);
}

std::string memory_text(double bytes) {
  char b[48];
  if (bytes >= 1099511627776.0) std::snprintf(b, sizeof b, "%.3g TiB", bytes / 1099511627776.0);
  else if (bytes >= 1073741824.0) std::snprintf(b, sizeof b, "%.3g GiB", bytes / 1073741824.0);
  else std::snprintf(b, sizeof b, "%.3g MiB", bytes / 1048576.0);
  return b;
}

double estimate_model_bytes(long long nodes, long long elements) {
  // 5 DOFs per node (docs/theory.md §2). A quad9 element couples 45 DOFs, so a sparse matrix holds about
  // 45·45 entries per element (less the sharing of nodes: on a structured mesh 4 elements share a corner
  // node, so ~2025/2.5 per element) at 12 bytes (value + index); the run keeps the stiffness, the mass and
  // the iteration matrix, assembles through triplets (16 bytes per element entry) and factorizes (a sparse
  // Cholesky factor holds at least as many entries as the matrix). The state vectors (u, v, a, forces and
  // the integrators' history, ~40 of them) add 8 bytes per DOF each. A lower bound: runs need more, never
  // less (measured in docs/guide/result-folders.md).
  const double n = static_cast<double>(nodes), e = static_cast<double>(elements), dofs = 5.0 * n;
  const double nnz = e * 2025.0 / 2.5;
  const double mesh = n * (3 * 8 + 3 * 8 + 16) + e * 9 * 4;  // X, normals, charts; connectivity
  return mesh + 3.0 * nnz * 12.0 + e * 2025.0 * 16.0 + 2.0 * nnz * 12.0 + 40.0 * dofs * 8.0;
}

void check_memory_estimate(long long nodes, long long elements, const std::string& where, const std::string& fix) {
  const double need = estimate_model_bytes(nodes, elements);
  const long long lim = g_memory_limit > 0 ? g_memory_limit : available_memory_bytes();
  if (lim <= 0 || need <= static_cast<double>(lim)) return;
  throw std::runtime_error((where.empty() ? std::string() : where + ": ") + std::to_string(nodes) + " nodes need at least " +
                           memory_text(need) + ", more than " +
                           (g_memory_limit > 0 ? "--max-memory " : "the available ") + memory_text(static_cast<double>(lim)) +
                           "; " + fix);
}

}  // namespace shelldyn
