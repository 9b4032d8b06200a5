// A case file turned into everything a solver needs: the validated CaseSpec, its Discretization
// (mesh, normals, charts, DOFs, loads, monitors) and the Model built on them.
#pragma once

#include "lib/io/case_file.hpp"
#include "lib/model/discretization.hpp"
#include "lib/model/model.hpp"

#include <memory>
#include <string>

namespace shelldyn {

// The element material of a case.
ShellMaterial shell_material(const CaseMaterial& m);

// Builds the Model of a discretization (copies the mesh, normals, DOF map and loads).
Model make_model(const Discretization& d, const CaseMaterial& material);

struct Problem {
  CaseSpec spec;
  Discretization disc;
  std::unique_ptr<Model> model;
  // The initial state: reference configuration, charts of the discretization, initial velocity.
  State initial_state() const;
};

// load_case + build_discretization + make_model; errors carry the case file's name.
Problem load_problem(const std::string& case_path);
Problem make_problem(CaseSpec spec);

}  // namespace shelldyn
