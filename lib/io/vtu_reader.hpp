// Reading back the ASCII VTU files of lib/io/vtu_writer.hpp (docs/manual.md §2.6, §1): the points and the
// point data arrays of a single-piece UnstructuredGrid, and the time a run's fields.pvd gives a VTU.
// Used to start a run from a velocity field (initial_velocity: {field: FILE.vtu}) and `static`/`modes`
// from a saved configuration (--state FILE.vtu). Binary or appended VTK data are refused with a message.
#pragma once

#include "lib/mesh/mesh.hpp"

#include <map>
#include <string>
#include <vector>

namespace shelldyn {

struct VtuPointData {
  std::string path;
  size_t num_points = 0;
  size_t num_cells = 0;
  std::vector<Vec3> points;  // current positions as written (x = X0 + displacement for shelldyn's files)
  struct Array {
    int components = 1;
    std::vector<double> values;  // components per point, interleaved
  };
  std::map<std::string, Array> arrays;  // point data by name

  bool has(const std::string& name) const { return arrays.count(name) != 0; }
  // The 3-component point array `name` as vectors. Throws std::runtime_error "PATH: ..." if it is
  // missing, has another number of components, or holds a NaN/Inf (naming the point).
  std::vector<Vec3> vectors(const std::string& name) const;
};

// Throws std::runtime_error "PATH: reason (how to fix)" when the file cannot be read, is not an
// UnstructuredGrid with one Piece, or an array's values do not match its declared size.
VtuPointData read_vtu(const std::string& path);

// The time at which a run wrote `vtu_path`: looked up in the fields.pvd of its run folder
// (DIR/fields/step_N.vtu is listed in DIR/fields.pvd). Returns false when no such collection lists it.
bool vtu_time_from_pvd(const std::string& vtu_path, double* time);

// Checks that `vtu` holds `num_nodes` points whose reference positions (points − displacement when a
// `displacement` array is present, else the points) match `X` to 1e-9 of the mesh size; throws
// std::runtime_error naming the file and the first node that differs (a field of another mesh).
void check_vtu_matches_mesh(const VtuPointData& vtu, const std::vector<Vec3>& X);

}  // namespace shelldyn
