// libFuzzer target: the case-file reader (lib/io/case_file.hpp) and the validation of the integrator
// block that `shelldyn check` and `shelldyn run` share (integrators/runs/case_integrator.hpp).
//
// Contract under test: any byte string either yields a CaseSpec or throws std::runtime_error /
// std::invalid_argument with a message. Anything else (another exception type, a crash, a sanitizer
// report, a hang) is a finding. Run with scripts/fuzz.sh.
#include "integrators/runs/case_integrator.hpp"
#include "lib/io/case_file.hpp"

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const shelldyn::CaseSpec spec = shelldyn::load_case_from_string(text, "fuzz.yaml", "/nonexistent");
    shelldyn::validate_case_integrator(spec);
  } catch (const std::runtime_error&) {
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
