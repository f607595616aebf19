#pragma once
// The rope of 4 elements (3 free dofs, 5 obstacle rows) and a reduced model of it
// written by hand, small enough that every online step can be checked on paper.
// Shared by the closed-form ROM tests.
//
// The rope (fom/problem.hpp): h = 1/4, element stiffness ν/h with ν = γ on the two
// left elements and 30 on the two right ones, so on the free nodes 1, 2, 3
//   K(γ) = 4γ [2 −1 0; −1 1 0; 0 0 0] + 120 [0 0 0; 0 1 −1; 0 −1 2],
// f = −load·h per node, obstacle ψ(x) = −0.2(sin πx − sin 3πx) − 0.5, which is
// (−0.5, −0.9, −0.5) at x = ¼, ½, ¾, and rows −w u_i + w ψ_i ≤ 0 with w = h = ¼
// inside (h/2 at the ends).
#include <Eigen/Dense>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include <contactrom/fom/problem.hpp>
#include <contactrom/fom/rope.hpp>
#include <contactrom/rom/offline.hpp>
#include <contactrom/rom/reduced_model.hpp>

namespace contactrom::test {

/// The rope of 4 elements under `load` (built once per load and test program).
inline const fom::Problem& rope4(double load = 200.0) {
  static std::map<double, std::unique_ptr<fom::Problem>> problems;
  auto& p = problems[load];
  if (!p) {
    fom::RopeOptions options;
    options.elements = 4;
    options.load = load;
    p = fom::make_rope_problem(options);
  }
  return *p;
}

/// The reduced model of rope4(load) with Φ = identity on the free nodes 1, 2, 3, the
/// stiffness terms of the left (coefficient γ) and right (coefficient 30) elements,
/// f̂ = −load/4 per node, a zero offset, and the given dictionary (5 × m) whose columns
/// stand for training parameters γ = 10, 20, … (database snapshots `snapshots`, or
/// 0 … m−1 if empty).
inline rom::ReducedModel hand_rope_model(const Eigen::MatrixXd& dictionary, double load = 200.0,
                                         std::vector<int> snapshots = {}) {
  const Eigen::Index m = dictionary.cols();
  rom::ReducedModelData d;
  d.options.delta = 1e-12;
  d.options.offset = rom::OffsetKind::Dirichlet;
  d.basis = Eigen::MatrixXd::Zero(5, 3);
  for (int i = 0; i < 3; ++i) d.basis(i + 1, i) = 1.0;
  d.singular_values = Eigen::Vector3d::Ones();
  d.offset_terms = {Eigen::VectorXd::Zero(5)};
  d.stiffness_terms = {4.0 * (Eigen::MatrixXd(3, 3) << 2, -1, 0, -1, 1, 0, 0, 0, 0).finished(),
                       4.0 * (Eigen::MatrixXd(3, 3) << 0, 0, 0, 0, 1, -1, 0, -1, 2).finished()};
  d.load_terms = Eigen::Vector3d::Constant(-load / 4.0);
  d.stiffness_offset_terms = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  d.dictionary = dictionary;
  for (Eigen::Index c = 0; c < m; ++c) {
    d.dictionary_snapshots.push_back(snapshots.empty() ? static_cast<int>(c) : snapshots[static_cast<size_t>(c)]);
    d.dictionary_parameters.push_back(Eigen::VectorXd::Constant(1, 10.0 * static_cast<double>(c + 1)));
  }
  d.primal_snapshots = Eigen::MatrixXd::Zero(5, m);
  return rom::ReducedModel(rope4(load), std::move(d));
}

/// The dictionary [e₁, 3e₂, e₃]: one column per interior node, the middle one scaled
/// so that a greedy picks it first (and, under load 200 at γ = 10, must remove it).
inline Eigen::MatrixXd unit_rope_dictionary() {
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(5, 3);
  d(1, 0) = 1.0, d(2, 1) = 3.0, d(3, 2) = 1.0;
  return d;
}

/// A ROM of the rope of 8 elements built from its FOM snapshots (the 9 training
/// values of γ, δ = 1e-12), with the rope's constraint operator (constant: C = −diag(w),
/// g = −wψ on every dof). Built once per test program.
struct RopeSnapshotRom {
  std::unique_ptr<fom::Problem> problem;
  rom::SnapshotDatabase db;
  std::unique_ptr<rom::ReducedModel> model;
  fom::ConstraintMatrix c;
  Eigen::VectorXd g;
  RopeSnapshotRom() {
    fom::RopeOptions options;
    options.elements = 8;
    problem = fom::make_rope_problem(options);
    rom::OfflineOptions off;
    off.threads = 1;
    db = rom::generate_snapshots(*problem, 9, off);
    rom::ReducedModelOptions ro;
    ro.delta = 1e-12;
    model = std::make_unique<rom::ReducedModel>(*problem, db, ro);
    problem->contact().assemble(problem->contact().search(Eigen::VectorXd::Zero(problem->num_dofs())), c, g);
  }
};

inline const RopeSnapshotRom& rope_snapshot_rom() {
  static const RopeSnapshotRom rom;
  return rom;
}

}  // namespace contactrom::test
