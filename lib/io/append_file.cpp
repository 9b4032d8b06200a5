#include "lib/io/append_file.hpp"
#include "lib/io/result_folder.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace shelldyn {
namespace {
std::string write_error_reason(int err) {
  return err == ENOSPC ? std::string("the disk is full (free space and rerun)") : std::string(std::strerror(err));
}
std::string file_name(const std::string& path) { return std::filesystem::path(path).filename().string(); }
}  // namespace

AppendFile::AppendFile(const std::string& path, const std::string& header) : path_(path), name_(file_name(path)) {
  record_output(path);  // the result folder's manifest (lib/io/result_folder.hpp)
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_APPEND | O_CLOEXEC, 0644);
  if (fd_ < 0) throw std::runtime_error(path + ": cannot create " + name_ + ": " + std::strerror(errno));
  append(header + "\n");
}

AppendFile::AppendFile(const std::string& path, const std::string& header, long long keep_bytes)
    : path_(path), name_(file_name(path)) {
  std::FILE* in = std::fopen(path.c_str(), "rb");
  if (!in) throw std::runtime_error(path + ": cannot reopen " + name_ + " to resume: " + std::strerror(errno));
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
  if (fd_ < 0) throw std::runtime_error(path + ": cannot append to " + name_ + ": " + std::strerror(errno));
  bytes_ = keep_bytes;
}

AppendFile::~AppendFile() {
  if (fd_ >= 0) ::close(fd_);
}

long long AppendFile::bytes() const { return fd_ >= 0 ? bytes_ : 0; }

void AppendFile::sync() {
  if (fd_ >= 0 && ::fsync(fd_) != 0) throw std::runtime_error(path_ + ": cannot write " + name_ + ": " + write_error_reason(errno));
}

void AppendFile::append(const std::string& text) {
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
  throw std::runtime_error(path_ + ": cannot write " + name_ + ": " + write_error_reason(err));
}

}  // namespace shelldyn
