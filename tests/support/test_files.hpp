// Files for the unit tests that write and read outputs: a fresh scratch folder, a whole file as text, and the
// message of the error a call throws. Header-only; shared by tests/lib/ and tests/integrators/.
#pragma once

#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <sstream>
#include <stdexcept>
#include <string>

namespace shelldyn::testing {

// A fresh, empty folder <system temp>/shelldyn_test_NAME (what a previous run left there is removed first),
// with the given subfolders. Give every test its own NAME: ctest runs the tests of one binary as parallel
// processes.
inline std::filesystem::path scratch_dir(const std::string& name, std::initializer_list<const char*> subfolders = {}) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("shelldyn_test_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  for (const char* sub : subfolders) std::filesystem::create_directories(dir / sub);
  return dir;
}

// The whole file as text ("" when it cannot be opened: the assertions on its content then fail).
inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline void write_text(const std::filesystem::path& p, const std::string& s) { std::ofstream(p) << s; }

// what() of the exception f throws, or "(no error)" when it throws none.
inline std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace shelldyn::testing
