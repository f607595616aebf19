// Tests of rom/online_evaluation.hpp: the errors of evaluate_online against values
// computed by hand (the H¹ norm of a P1 function on the 4-element rope, the
// weighted L² norm of a pressure), the summary statistics (means and maxima over
// the relative rows, absolute rows left out, counts of non-converged queries and FOM
// failures, median time), the CSV rows written back and read, the FOM references,
// median(), the timing samples, and the refusals of unknown methods and options.
// The online solver is a stand-in that returns prescribed results.
#define BOOST_TEST_MODULE rom_online_evaluation
#include <boost/test/unit_test.hpp>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "common/run_command.hpp"
#include "common/tiny_rope.hpp"
#include <contactrom/core/errors.hpp>
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/rom/online_evaluation.hpp>
#include <contactrom/rom/online_methods.hpp>
#include <contactrom/rom/online_timing.hpp>

using namespace contactrom;
using Eigen::VectorXd;

namespace {

/// Returns a prescribed result per query (keyed by γ).
class FixedSolver final : public rom::OnlineSolver {
 public:
  explicit FixedSolver(const rom::ReducedModel& model) : m_model(model) {}
  std::string name() const override { return "fixed"; }
  const rom::ReducedModel& model() const override { return m_model; }
  /// The prescribed answer, taking the prescribed time on the query's clock.
  void solve_reduced(const fom::Param& mu, rom::OnlineResult& res) const override {
    const auto t0 = std::chrono::steady_clock::now();
    res = m_results.at(mu(0));
    while (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() < res.time_s) {
    }
  }
  Eigen::VectorXd reconstruct_primal(const rom::OnlineResult& res) const override { return m_results.at(res.mu(0)).u; }
  std::map<double, rom::OnlineResult> m_results;

 private:
  const rom::ReducedModel& m_model;
};

/// ‖u‖²_H¹ = Σ_e ∫ u² + u'² of the P1 function with nodal values u on the uniform
/// rope of 4 elements (h = ¼): ∫_e u² = h(a² + ab + b²)/3, ∫_e u'² = (b − a)²/h.
double h1_squared(const VectorXd& u) {
  const double h = 0.25;
  double s = 0.0;
  for (int e = 0; e < 4; ++e) {
    const double a = u(e), b = u(e + 1);
    s += h * (a * a + a * b + b * b) / 3.0 + (b - a) * (b - a) / h;
  }
  return s;
}

/// Σ_s w_s λ_s² with the rope's weights (h/2, h, h, h, h/2).
double l2_squared(const VectorXd& lambda) {
  const VectorXd w = (VectorXd(5) << 0.125, 0.25, 0.25, 0.25, 0.125).finished();
  return w.dot(lambda.cwiseAbs2());
}

fom::Param gamma_value(double g) { return VectorXd::Constant(1, g); }

struct Case {
  VectorXd u_ref, lambda_ref, u, lambda;
  std::vector<int> selected;  // dictionary columns
  int iterations;
  double time;
  bool converged;
  Status fom_status;
};

/// Four queries: two ordinary ones, one whose reference displacement is zero
/// (absolute errors), one not converged with a failed reference.
std::map<double, Case> cases() {
  std::map<double, Case> c;
  const VectorXd e1 = VectorXd::Unit(5, 1), e2 = VectorXd::Unit(5, 2), e3 = VectorXd::Unit(5, 3);
  const VectorXd u = (VectorXd(5) << 0, -0.5, -0.8, -0.5, 0).finished();
  const VectorXd lam = (VectorXd(5) << 0, 100, 0, 80, 0).finished();
  c[15.0] = {u, lam, u + 0.01 * e2, lam + 10.0 * e1, {0, 2}, 3, 3e-6, true, Status::Success};
  c[25.0] = {u, lam, u - 0.02 * e1 + 0.01 * e3, lam, {0}, 5, 1e-6, true, Status::Success};
  c[35.0] = {VectorXd::Zero(5), VectorXd::Zero(5), 0.001 * e2, 2.0 * e1, {}, 1, 2e-6, true, Status::Success};
  c[45.0] = {u, lam, u, 0.5 * lam, {1, 2}, 50, 9e-6, false, Status::NoConvergence};
  return c;
}

struct Evaluated {
  rom::ReducedModel model = test::hand_rope_model(test::unit_rope_dictionary(), 200.0, {4, 7, 9});
  FixedSolver solver{model};
  std::vector<fom::Param> params;
  rom::EvaluationSummary summary;
  Evaluated() {
    std::vector<fom::FomSolution> refs;
    for (const auto& [g, c] : cases()) {
      rom::OnlineResult r;
      r.mu = gamma_value(g), r.u = c.u, r.lambda = c.lambda, r.selected = c.selected, r.iterations = c.iterations;
      r.time_s = c.time, r.converged = c.converged;
      r.status = c.converged ? Status::Success : Status::NoConvergence;
      r.coefficients = VectorXd::Ones(static_cast<Eigen::Index>(c.selected.size()));
      solver.m_results[g] = r;
      fom::FomSolution s;
      s.mu = gamma_value(g), s.u = c.u_ref, s.lambda = c.lambda_ref, s.status = c.fom_status;
      refs.push_back(s);
      params.push_back(gamma_value(g));
    }
    summary = rom::evaluate_online(solver, params, refs);
  }
};

const Evaluated& evaluated() {
  static const Evaluated e;
  return e;
}

}  // namespace

BOOST_AUTO_TEST_CASE(errors_are_the_hand_computed_norms) {
  const rom::EvaluationSummary& s = evaluated().summary;
  BOOST_REQUIRE(s.rows.size() == 4u);
  const auto all = cases();
  size_t i = 0;
  for (const auto& [g, c] : all) {
    const rom::EvaluationRow& row = s.rows[i++];
    BOOST_TEST_CONTEXT("gamma " << g) {
      BOOST_TEST(row.mu(0) == g);
      const bool absolute = c.u_ref.norm() == 0.0;
      BOOST_TEST(row.absolute_errors == absolute);
      const double primal = std::sqrt(h1_squared(c.u - c.u_ref) / (absolute ? 1.0 : h1_squared(c.u_ref)));
      const double dual = std::sqrt(l2_squared(c.lambda - c.lambda_ref) / (absolute ? 1.0 : l2_squared(c.lambda_ref)));
      BOOST_TEST(std::abs(row.primal_error - primal) <= 1e-14 * (1.0 + primal));
      BOOST_TEST(std::abs(row.dual_error - dual) <= 1e-14 * (1.0 + dual));
      BOOST_TEST(row.sparsity == static_cast<int>(c.selected.size()));
      BOOST_TEST(row.iterations == c.iterations);
      BOOST_TEST(row.converged == c.converged);
      BOOST_TEST(row.fom_status == c.fom_status);
    }
  }
  // First row by hand: u − u_ref = 0.01 at node 2 (two elements, a = 0, b = 0.01 and
  // back): ‖·‖² = 2(h b²/3 + b²/h) = 2(0.01²/12 + 4·0.01²).
  BOOST_TEST(std::abs(h1_squared(0.01 * VectorXd::Unit(5, 2)) - 2.0 * (1e-4 / 12.0 + 4e-4)) <= 1e-18);
  // Selected columns are reported as database snapshots: columns 0, 1, 2 are 4, 7, 9.
  BOOST_TEST(s.rows[0].selected == (std::vector<int>{4, 9}));
  BOOST_TEST(s.rows[3].selected == (std::vector<int>{7, 9}));
}

BOOST_AUTO_TEST_CASE(summary_statistics_leave_absolute_rows_and_failed_references_out_of_the_error_means) {
  const rom::EvaluationSummary& s = evaluated().summary;
  BOOST_TEST(s.method == "fixed");
  BOOST_TEST(s.dictionary_size == 3);
  BOOST_TEST(s.primal_rank == 3);
  BOOST_TEST(s.absolute_error_rows == 1);
  // Two rows count: γ = 35 has absolute errors, γ = 45 a reference that did not
  // converge (its pressure error of 0.5, the largest, measures nothing).
  double mean_p = 0.0, max_p = 0.0, mean_d = 0.0, max_d = 0.0, failed_dual = 0.0;
  for (const auto& row : s.rows) {
    if (row.fom_status != Status::Success) failed_dual = row.dual_error;
    if (row.absolute_errors || row.fom_status != Status::Success) continue;
    mean_p += row.primal_error / 2.0, max_p = std::max(max_p, row.primal_error);
    mean_d += row.dual_error / 2.0, max_d = std::max(max_d, row.dual_error);
  }
  BOOST_TEST(failed_dual > max_d);
  BOOST_TEST(std::abs(s.mean_primal_error - mean_p) <= 1e-15 * max_p);
  BOOST_TEST(s.max_primal_error == max_p);
  BOOST_TEST(std::abs(s.mean_dual_error - mean_d) <= 1e-15 * max_d);
  BOOST_TEST(s.max_dual_error == max_d);
  // Sparsity 2, 1, 0, 2; iterations 3, 5, 1, 50; times 3, 1, 2, 9 µs.
  BOOST_TEST(s.mean_sparsity == 1.25);
  BOOST_TEST(s.max_sparsity == 2);
  BOOST_TEST(s.mean_iterations == 14.75);
  // A query's time is its method's plus the full-order contact check's.
  const double prescribed[] = {3e-6, 1e-6, 2e-6, 9e-6};
  std::vector<double> times;
  double mean_t = 0.0;
  for (size_t i = 0; i < s.rows.size(); ++i) {
    BOOST_TEST(s.rows[i].time_s >= prescribed[i]);
    BOOST_TEST(s.rows[i].time_s <= prescribed[i] + 1e-3);
    times.push_back(s.rows[i].time_s);
    mean_t += s.rows[i].time_s / 4.0;
  }
  BOOST_TEST(std::abs(s.mean_time_s - mean_t) <= 1e-15);
  BOOST_TEST(s.median_time_s == rom::median(times));
  BOOST_TEST(s.nonconverged == 1);
  BOOST_TEST(s.fom_failures == 1);
}

BOOST_AUTO_TEST_CASE(csv_rows_read_back) {
  const Evaluated& e = evaluated();
  const std::string dir = test::temp_dir(), path = dir + "/rows.csv";
  rom::write_evaluation_csv(path, test::rope4(), e.summary);
  std::istringstream in(test::slurp(path));
  std::string line;
  std::getline(in, line);
  BOOST_TEST(line == "gamma,primal_error,dual_error,sparsity,iterations,time_s,converged,status,selected,errors,penetration,separation,primal_estimate,dual_estimate,reference_status");
  for (const rom::EvaluationRow& row : e.summary.rows) {
    BOOST_REQUIRE(std::getline(in, line));
    std::vector<std::string> f;
    std::stringstream fields(line);
    for (std::string x; std::getline(fields, x, ',');) f.push_back(x);
    BOOST_REQUIRE(f.size() == 15u);
    BOOST_TEST(std::stod(f[0]) == row.mu(0));  // numbers written to read back exactly
    BOOST_TEST(std::stod(f[1]) == row.primal_error);
    BOOST_TEST(std::stod(f[2]) == row.dual_error);
    BOOST_TEST(std::stoi(f[3]) == row.sparsity);
    BOOST_TEST(std::stoi(f[4]) == row.iterations);
    BOOST_TEST(std::stod(f[5]) == row.time_s);
    BOOST_TEST(f[6] == (row.converged ? "1" : "0"));
    BOOST_TEST(f[7] == to_string(row.status));
    std::string selected;
    for (size_t j = 0; j < row.selected.size(); ++j) selected += (j ? " " : "") + std::to_string(row.selected[j]);
    BOOST_TEST(f[8] == selected);
    BOOST_TEST(f[9] == (row.absolute_errors ? "absolute" : "relative"));
    BOOST_TEST(f[14] == to_string(row.fom_status));
  }
  BOOST_TEST(!std::getline(in, line));
  std::filesystem::remove_all(dir);
}

BOOST_AUTO_TEST_CASE(references_are_the_fom_solutions) {
  const fom::ActiveSetSolver solver(test::rope4());
  const std::vector<fom::Param> params = {gamma_value(10.0), gamma_value(22.0), gamma_value(47.0)};
  const auto refs = rom::compute_references(solver, params, 2);
  BOOST_REQUIRE(refs.size() == 3u);
  for (size_t i = 0; i < 3; ++i) {
    const fom::FomSolution s = solver.solve(params[i]);
    BOOST_TEST((refs[i].mu - params[i]).norm() == 0.0);
    BOOST_TEST((refs[i].u - s.u).norm() == 0.0);
    BOOST_TEST((refs[i].lambda - s.lambda).norm() == 0.0);
  }
  // At γ = 10 (load 200) the closed-form solution: u = (0, −½, −0.8125, −½, 0).
  BOOST_TEST((refs[0].u - (VectorXd(5) << 0, -0.5, -0.8125, -0.5, 0).finished()).norm() <= 1e-12);
}

BOOST_AUTO_TEST_CASE(median_and_timing_samples) {
  BOOST_TEST(rom::median({}) == 0.0);
  BOOST_TEST(rom::median({3.0, 1.0, 2.0}) == 2.0);
  BOOST_TEST(rom::median({4.0, 1.0, 3.0, 2.0}) == 2.5);
  rom::OnlineSamples samples;
  samples.core = {1.0, 5.0, 3.0};
  samples.total = {2.0, 6.0, 4.0};
  rom::OnlineTiming t = samples.timing();
  BOOST_TEST(t.median_core_s == 3.0);
  BOOST_TEST(t.median_total_s == 4.0);
  BOOST_TEST(t.median_without_operators_s == -1.0);  // not measured
  BOOST_TEST(t.queries == 3);
  samples.without = {0.5, 0.7, 0.6};
  BOOST_TEST(samples.timing().median_without_operators_s == 0.6);
  // A timed pass appends one sample per query.
  rom::OnlineSamples pass;
  rom::time_online_pass(evaluated().solver, evaluated().params, pass);
  BOOST_TEST(pass.core.size() == 4u);
  BOOST_TEST(pass.core[0] >= 3e-6);  // the solver's own core time and the contact check's
  BOOST_TEST(pass.core[0] <= 3e-6 + 1e-3);
  BOOST_TEST(pass.without.empty());  // operator_time_s = −1: not measured
}

BOOST_AUTO_TEST_CASE(unknown_methods_and_options_are_refused) {
  BOOST_CHECK_THROW(rom::check_online_method("no-such-method"), InputError);
  BOOST_CHECK_NO_THROW(rom::check_online_method("greedy"));
  rom::OnlineSolverOptions options;
  options.extra["colour"] = "blue";
  BOOST_CHECK_THROW(rom::validate_online_options("greedy", options), InputError);
  BOOST_CHECK_THROW(rom::make_online_solver("no-such-method", evaluated().model), InputError);
}
