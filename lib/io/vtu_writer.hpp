// VTK XML output of the shell state for ParaView (architecture.md §5): one ASCII .vtu
// (UnstructuredGrid) per output step, and a .pvd collection listing them with their times.
//
// - Points are the CURRENT positions x = X0 + d, so a .pvd animates without filters; the point data
//   "displacement" recovers the initial configuration as x - displacement.
// - Cells have VTK type 28 (VTK_BIQUADRATIC_QUAD); the connectivity is written in the mesh's own
//   order, because Gmsh type 10 and VTK 28 share the node order of lib/mesh/mesh.hpp.
// - Point data "displacement", "velocity", "director" (3 components each), then the optional extra
//   point scalars; cell data are the optional extra cell scalars.
// Values use %.17g, so the files are exact (and large; this is for inspection, not archiving).
#pragma once

#include "lib/mesh/mesh.hpp"

#include <string>
#include <utility>
#include <vector>

namespace shelldyn {

struct ScalarField {
  std::string name;
  std::vector<double> values;  // `components` per point (point data) or per element (cell data)
  int components = 1;          // > 1: a vector/tensor field, values interleaved per point/element
  // Names of the components, written as ComponentName0.. attributes (ParaView shows them instead of
  // 0, 1, 2). Empty: X, Y, Z for a 3-component field, no names otherwise.
  std::vector<std::string> component_names = {};
};

struct VtuFields {
  std::vector<Vec3> displacement;  // d, one per node
  std::vector<Vec3> velocity;      // translational velocity, one per node
  std::vector<Vec3> director;      // current unit director p, one per node
  std::vector<ScalarField> point_scalars;
  std::vector<ScalarField> cell_scalars;
};

// Writes `path` (parent folder must exist). Throws std::invalid_argument if a field has the wrong
// length or an empty/duplicate name, std::runtime_error if the file cannot be written.
void write_vtu(const std::string& path, const Mesh& mesh, const VtuFields& fields);

// A ParaView collection file that is rewritten completely on every add(), so an interrupted run
// still leaves a valid .pvd listing every step written so far. Files are recorded relative to the
// .pvd's folder.
class PvdWriter {
 public:
  explicit PvdWriter(std::string pvd_path);
  // Records (time, file) and rewrites the .pvd (via a temporary file and a rename). `file` is
  // relative to the .pvd's folder, e.g. "fields/step_000010.vtu". Throws std::runtime_error on I/O errors.
  void add(double time, const std::string& file);
  const std::vector<std::pair<double, std::string>>& entries() const { return entries_; }
  // Resume (checkpoint restart): the entries up to the checkpoint; the file is rewritten at the next add().
  void restore(std::vector<std::pair<double, std::string>> entries) { entries_ = std::move(entries); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::vector<std::pair<double, std::string>> entries_;
};

// "step_000042.vtu": the naming of fields/ in architecture.md §5 (6 digits, more if needed).
std::string vtu_step_file_name(long long output_step);

}  // namespace shelldyn
