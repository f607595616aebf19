// ReducedModel (rom/reduced_model.hpp): the offline data of the warm start — the
// reduced coordinates of every snapshot and the interpolation stencil of training
// parameters around a query — on hertz (one parameter, 12 snapshots) and ironing2
// (a 3 × 3 tensor grid of two parameters).
#define BOOST_TEST_MODULE rom_reduced_model
#include <boost/test/unit_test.hpp>

#include <memory>

#include <contactrom/fom/problem.hpp>
#include <contactrom/core/errors.hpp>
#include <contactrom/rom/offline.hpp>
#include <contactrom/rom/online_methods.hpp>
#include <contactrom/rom/reduced_model.hpp>

using namespace contactrom;

namespace {

struct Built {
  std::unique_ptr<fom::Problem> problem;
  rom::SnapshotDatabase db;
  std::unique_ptr<rom::ReducedModel> model;
  Built(const std::string& name, int n, double delta) : problem(fom::make_problem(name)) {
    rom::OfflineOptions off;
    off.threads = 2;
    db = rom::generate_snapshots(*problem, n, off);
    rom::ReducedModelOptions options;
    options.delta = delta;
    model = std::make_unique<rom::ReducedModel>(*problem, db, options);
  }
};

Built& hertz12() {
  static Built b("hertz", 12, 1e-10);
  return b;
}

/// Σ w_j μ_j and Σ w_j over a stencil.
std::pair<Eigen::VectorXd, double> weighted_parameter(const rom::ReducedModel& model,
                                                      const std::vector<rom::ReducedModel::StencilPoint>& stencil) {
  Eigen::VectorXd p = Eigen::VectorXd::Zero(model.dictionary_parameters()[0].size());
  double total = 0.0;
  for (const auto& s : stencil) {
    p += s.weight * model.dictionary_parameters()[static_cast<size_t>(s.column)];
    total += s.weight;
  }
  return {p, total};
}

}  // namespace

BOOST_AUTO_TEST_CASE(snapshot_coordinates_are_the_projections_of_the_snapshots) {
  // û_j = Φᵀ(u_j − u_off(μ_j)): Φû_j + u_off(μ_j) is the snapshot up to the POD
  // truncation (δ = 1e-10 of the energy), and Φᵀ of it gives û_j back.
  const Built& b = hertz12();
  const rom::ReducedModel& model = *b.model;
  BOOST_REQUIRE(model.snapshot_coordinates().rows() == model.primal_rank());
  BOOST_REQUIRE(model.snapshot_coordinates().cols() == model.dictionary_size());
  for (int c = 0; c < model.dictionary_size(); ++c) {
    const int j = model.dictionary_snapshots()[static_cast<size_t>(c)];
    const fom::Param mu = b.db.parameter(j);
    const Eigen::VectorXd u = b.db.primal.col(j) + b.problem->lifting(mu);
    const Eigen::VectorXd back = model.reconstruct_primal(model.snapshot_coordinates().col(c), mu);
    BOOST_TEST((back - u).norm() <= 1e-4 * u.norm(), "snapshot " << j);
    const Eigen::VectorXd again = model.basis().transpose() * (back - model.offset(mu));
    BOOST_TEST((again - model.snapshot_coordinates().col(c)).norm() <= 1e-10 * again.norm(), "snapshot " << j);
  }
}

BOOST_AUTO_TEST_CASE(primal_snapshots_are_kept_as_the_database_stores_them) {
  // One convention from the database to the convex hull: the kept primal snapshots
  // are the stored u − u_lift, bitwise, whatever the offset; the coordinates are
  // measured from the offset, Φᵀ(u − u_off) = Φᵀ(u − u_lift) + reduced_lifting(μ).
  Built& b = hertz12();
  for (const rom::OffsetKind kind : {rom::OffsetKind::Harmonic, rom::OffsetKind::Dirichlet}) {
    rom::ReducedModelOptions options;
    options.delta = 1e-10;
    options.offset = kind;
    const rom::ReducedModel model(*b.problem, b.db, options);
    BOOST_REQUIRE(model.has_primal_snapshots());
    for (int c = 0; c < model.dictionary_size(); ++c) {
      BOOST_TEST_CONTEXT("offset " << static_cast<int>(kind) << ", column " << c) {
        const int j = model.dictionary_snapshots()[static_cast<size_t>(c)];
        const fom::Param mu = b.db.parameter(j);
        BOOST_TEST((model.primal_snapshots().col(c) - b.db.primal.col(j)).cwiseAbs().maxCoeff() == 0.0);
        const Eigen::VectorXd u = b.db.primal.col(j) + b.problem->lifting(mu);
        const Eigen::VectorXd coords = model.basis().transpose() * (u - model.offset(mu));
        BOOST_TEST((coords - model.snapshot_coordinates().col(c)).norm() <= 1e-12 * coords.norm());
        const Eigen::VectorXd lift = model.basis().transpose() * (b.problem->lifting(mu) - model.offset(mu));
        BOOST_TEST((lift - model.reduced_lifting(mu)).norm() <= 1e-13 * (1.0 + lift.norm()));
        if (kind == rom::OffsetKind::Dirichlet) BOOST_TEST(model.reduced_lifting(mu).cwiseAbs().maxCoeff() == 0.0);
      }
    }
  }
}

BOOST_AUTO_TEST_CASE(one_parameter_stencil_brackets_the_query) {
  const rom::ReducedModel& model = *hertz12().model;
  const auto& params = model.dictionary_parameters();
  // At a training parameter: that column alone, weight 1.
  for (int c = 0; c < model.dictionary_size(); ++c) {
    const auto stencil = model.interpolation_stencil(params[static_cast<size_t>(c)]);
    BOOST_REQUIRE(stencil.size() == 1u);
    BOOST_TEST(stencil[0].column == c);
    BOOST_TEST(stencil[0].weight == 1.0);
  }
  // Between two: the bracketing pair, positive weights that sum to 1 and reproduce μ
  // (linear interpolation is exact for the parameter itself).
  for (double d : {0.026, 0.1, 0.137, 0.2999}) {
    const fom::Param mu = Eigen::VectorXd::Constant(1, d);
    const auto stencil = model.interpolation_stencil(mu);
    BOOST_TEST_CONTEXT("d = " << d) {
      BOOST_REQUIRE(stencil.size() == 2u);
      double lo = 1e300, hi = -1e300;
      for (const auto& s : stencil) {
        BOOST_TEST(s.weight > 0.0);
        lo = std::min(lo, params[static_cast<size_t>(s.column)](0));
        hi = std::max(hi, params[static_cast<size_t>(s.column)](0));
      }
      BOOST_TEST(lo < d);
      BOOST_TEST(hi > d);
      for (const fom::Param& p : params) BOOST_TEST(!(p(0) > lo && p(0) < hi), "a training parameter inside the bracket");
      const auto [p, total] = weighted_parameter(model, stencil);
      BOOST_TEST(std::abs(total - 1.0) <= 1e-14);
      BOOST_TEST(std::abs(p(0) - d) <= 1e-14);
    }
  }
  // Below the training range (hertz's training set starts at 0.3/12): clamped to the
  // lowest training parameter.
  const auto below = model.interpolation_stencil(Eigen::VectorXd::Constant(1, 0.001));
  BOOST_REQUIRE(below.size() == 1u);
  double lowest = 1e300;
  for (const fom::Param& p : params) lowest = std::min(lowest, p(0));
  BOOST_TEST(params[static_cast<size_t>(below[0].column)](0) == lowest);
}

BOOST_AUTO_TEST_CASE(two_parameter_stencil_is_the_enclosing_cell) {
  // ironing2 level 1: the 3 × 3 grid {0, 2, 4} × {0.1, 0.2, 0.3}.
  Built b("ironing2", 1, 1e-8);
  const rom::ReducedModel& model = *b.model;
  BOOST_REQUIRE(model.dictionary_size() == 9);
  const fom::Param mu = Eigen::Vector2d(2.5, 0.13);
  const auto stencil = model.interpolation_stencil(mu);
  BOOST_REQUIRE(stencil.size() == 4u);
  for (const auto& s : stencil) {
    const fom::Param& p = model.dictionary_parameters()[static_cast<size_t>(s.column)];
    BOOST_TEST((std::abs(p(0) - 2.0) < 1e-12 || std::abs(p(0) - 4.0) < 1e-12));
    BOOST_TEST((std::abs(p(1) - 0.1) < 1e-12 || std::abs(p(1) - 0.2) < 1e-12));
    BOOST_TEST(s.weight > 0.0);
  }
  const auto [p, total] = weighted_parameter(model, stencil);
  BOOST_TEST(std::abs(total - 1.0) <= 1e-14);
  BOOST_TEST((p - mu).norm() <= 1e-14);
  // On a cell edge: the two corners of that edge.
  BOOST_TEST(model.interpolation_stencil(Eigen::Vector2d(2.0, 0.25)).size() == 2u);
}

BOOST_AUTO_TEST_CASE(two_contact_pairs_give_one_column_per_pair) {
  // punch_beam: the punch on the beam and the beam on the foundation. Every
  // dictionary column lives on one pair's rows; the columns of one snapshot
  // (siblings, same parameter and primal snapshot) add up to its pressure; the
  // unsplit model has one column per snapshot. A query at a training parameter
  // reproduces its snapshot with the split dictionary.
  Built b("punch_beam", 8, 1e-10);
  const rom::ReducedModel& model = *b.model;
  const fom::ContactModel& contact = b.problem->contact();
  BOOST_REQUIRE(contact.num_pairs() == 2);
  BOOST_TEST(model.dictionary_size() > b.db.num_snapshots());
  for (int p = 0; p < model.dictionary_size(); ++p) {
    int pair = -1;
    for (int s = 0; s < model.dictionary().rows(); ++s)
      if (model.dictionary()(s, p) != 0.0) {
        if (pair < 0) pair = contact.pair_of_row(s);
        BOOST_TEST(contact.pair_of_row(s) == pair, "column " << p << " row " << s);
      }
  }
  for (int j = 0; j < b.db.num_snapshots(); ++j) {
    Eigen::VectorXd sum = Eigen::VectorXd::Zero(model.dictionary().rows());
    int found = 0;
    for (int p = 0; p < model.dictionary_size(); ++p)
      if (model.dictionary_snapshots()[p] == j) {
        sum += model.dictionary().col(p);
        ++found;
        BOOST_TEST((model.dictionary_parameters()[p] - b.db.parameter(j)).norm() == 0.0);
      }
    BOOST_TEST(found >= 1);
    for (int p = 0; p < model.dictionary_size(); ++p)
      if (model.dictionary_snapshots()[p] == j) BOOST_TEST(model.sibling_columns(p).size() == static_cast<size_t>(found));
    BOOST_TEST((sum - b.db.dual.col(j)).norm() == 0.0, "snapshot " << j);
  }
  rom::ReducedModelOptions whole;
  whole.delta = 1e-10;
  whole.split_pairs = false;
  BOOST_TEST(rom::ReducedModel(*b.problem, b.db, whole).dictionary_size() == b.db.num_snapshots());
}

BOOST_AUTO_TEST_CASE(delta_one_keeps_no_mode_and_every_method_runs_on_the_empty_basis) {
  // δ = 1 (inside the documented range [0, 1]) discards every mode: the basis is
  // empty, and every online method answers with the offset alone (no contact can be
  // enforced) instead of touching rows of an empty matrix.
  Built b("hertz", 6, 1.0);
  BOOST_TEST(b.model->primal_rank() == 0);
  const fom::Param mu = fom::Param::Constant(1, 0.1);
  for (const std::string& method : rom::online_solver_names()) {
    BOOST_TEST_CONTEXT(method) {
      std::unique_ptr<rom::OnlineSolver> solver;
      try {
        solver = rom::make_online_solver(method, *b.model);
      } catch (const InputError& e) {  // a method may refuse the empty basis, with a message
        BOOST_TEST(std::string(e.what()).size() > 0u);
        continue;
      }
      const rom::OnlineResult r = solver->solve(mu);
      BOOST_TEST(r.u.size() == b.problem->num_dofs());
      BOOST_TEST(r.u.allFinite());
      BOOST_TEST(r.lambda.allFinite());
    }
  }
}
