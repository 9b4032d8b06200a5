// A CSV result file that grows by whole rows: history.csv and bodies.csv (docs/guide/result-folders.md).
//
// Each append() reaches the file with one write(2) on an O_APPEND descriptor: a killed run leaves complete
// rows only, nothing is buffered in the process, and a short write (a full disk) is cut back so that no
// half row stays. bytes() is the resume position a checkpoint records; the resuming constructor keeps that
// many bytes and drops the rows written after the checkpoint.
#pragma once
#include <string>

namespace shelldyn {

class AppendFile {
 public:
  // Creates (truncates) `path`, records it in the result folder's manifest and writes `header` + "\n".
  AppendFile(const std::string& path, const std::string& header);
  // Resume: keeps the first `keep_bytes` bytes of the existing `path` and appends from there. Throws
  // std::runtime_error if the file cannot be read, its first line is not `header`, or it is shorter than
  // `keep_bytes` (or `keep_bytes` would cut into the header).
  AppendFile(const std::string& path, const std::string& header, long long keep_bytes);
  ~AppendFile();
  AppendFile(const AppendFile&) = delete;
  AppendFile& operator=(const AppendFile&) = delete;

  // One write(2) of `text` (whole rows ending in '\n'). Throws std::runtime_error naming the file and the
  // reason (a full disk says so); the file is closed after a failed write.
  void append(const std::string& text);
  long long bytes() const;  // bytes written so far, header included (0 once closed after an error)
  void sync();              // fsync(2); throws std::runtime_error on failure
  const std::string& path() const { return path_; }

 private:
  std::string path_, name_;  // name_: the file name, for messages ("history.csv")
  int fd_ = -1;
  long long bytes_ = 0;
};

}  // namespace shelldyn
