#include <contactrom/baselines/ipopt_qp.hpp>

#include <IpIpoptApplication.hpp>
#include <IpIpoptData.hpp>
#include <IpIpoptCalculatedQuantities.hpp>
#include <IpTNLP.hpp>

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include <contactrom/core/errors.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/core/stopwatch.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/fom/rigid_bodies.hpp>
#include <contactrom/fom/pairing_fixed_point.hpp>

namespace contactrom::baselines {

using fom::ConstraintMatrix;
using fom::FomSolution;
using fom::Pairing;
using fom::Param;
using fom::SparseMatrix;

namespace {

/// Ipopt's "minus infinity" for one-sided bounds (anything ≤ nlp_lower_bound_inf = -1e19).
constexpr double kMinusInfinity = -1e20;
constexpr double kPlusInfinity = 1e20;

/// K_ff, its lower triangle in coordinate form (the constant Ipopt Hessian) and, for
/// contact models with a pairing, a factorisation that gives the unconstrained
/// solution seeding the pairing fixed point.
struct FreeStiffness {
  SparseMatrix kff;  // full symmetric block on free dofs, for the objective and its gradient
  std::vector<int> h_row, h_col;
  std::vector<double> h_val;
  std::unique_ptr<Eigen::SimplicialLDLT<SparseMatrix>> ldlt;  // null when not needed
};

std::unique_ptr<FreeStiffness> extract_free_stiffness(const SparseMatrix& k, const std::vector<int>& free,
                                                     const std::vector<int>& free_index, bool factorise) {
  auto out = std::make_unique<FreeStiffness>();
  out->kff = fom::free_block(k, free_index, static_cast<int>(free.size()));
  for (int col = 0; col < out->kff.outerSize(); ++col)
    for (SparseMatrix::InnerIterator it(out->kff, col); it; ++it)
      if (it.row() >= col) {
        out->h_row.push_back(static_cast<int>(it.row()));
        out->h_col.push_back(col);
        out->h_val.push_back(it.value());
      }
  // A simplicial LDLᵀ (not the FOM's CHOLMOD path) keeps the reference independent.
  if (factorise) out->ldlt = std::make_unique<Eigen::SimplicialLDLT<SparseMatrix>>(out->kff);
  return out;
}

/// One QP of the pairing loop, on the free dofs x = u0_f:
///   min ½ xᵀ K_ff x − f_fᵀ x   s.t.   A x ≤ b,
/// A = rows of C kept (paired rows touching a free dof), columns mapped to free dofs,
/// b = g − C u_lift on those rows.
struct QpData {
  const FreeStiffness* k = nullptr;
  Eigen::VectorXd f;  // f_f
  std::vector<int> a_row, a_col;
  std::vector<double> a_val;
  Eigen::VectorXd b;
  std::vector<int> kept_rows;  // constraint row of each NLP constraint
  Eigen::VectorXd x0;          // starting point
  Eigen::VectorXd lambda0;     // starting multipliers (warm start), empty: none
};

/// The Ipopt view of QpData (Ipopt's TNLP interface, C-style indices).
class ContactQpNlp final : public Ipopt::TNLP {
 public:
  explicit ContactQpNlp(const QpData& data) : m_data(data) {}

  bool get_nlp_info(Ipopt::Index& n, Ipopt::Index& m, Ipopt::Index& nnz_jac_g, Ipopt::Index& nnz_h_lag,
                    IndexStyleEnum& index_style) override {
    n = static_cast<Ipopt::Index>(m_data.f.size());
    m = static_cast<Ipopt::Index>(m_data.b.size());
    nnz_jac_g = static_cast<Ipopt::Index>(m_data.a_val.size());
    nnz_h_lag = static_cast<Ipopt::Index>(m_data.k->h_val.size());
    index_style = C_STYLE;
    return true;
  }

  bool get_bounds_info(Ipopt::Index n, Ipopt::Number* x_l, Ipopt::Number* x_u, Ipopt::Index m, Ipopt::Number* g_l,
                       Ipopt::Number* g_u) override {
    std::fill(x_l, x_l + n, kMinusInfinity);
    std::fill(x_u, x_u + n, kPlusInfinity);
    std::fill(g_l, g_l + m, kMinusInfinity);
    for (Ipopt::Index i = 0; i < m; ++i) g_u[i] = m_data.b(i);
    return true;
  }

  bool get_starting_point(Ipopt::Index n, bool init_x, Ipopt::Number* x, bool init_z, Ipopt::Number* z_l,
                          Ipopt::Number* z_u, Ipopt::Index m, bool init_lambda, Ipopt::Number* lambda) override {
    if (init_x) std::copy(m_data.x0.data(), m_data.x0.data() + n, x);
    // No finite variable bounds: z_L, z_U are never used but must be set.
    if (init_z) std::fill(z_l, z_l + n, 0.0), std::fill(z_u, z_u + n, 0.0);
    if (init_lambda) {
      if (m_data.lambda0.size() != m) return false;
      std::copy(m_data.lambda0.data(), m_data.lambda0.data() + m, lambda);
    }
    return true;
  }

  bool eval_f(Ipopt::Index n, const Ipopt::Number* x, bool, Ipopt::Number& obj_value) override {
    const Eigen::Map<const Eigen::VectorXd> xv(x, n);
    obj_value = 0.5 * xv.dot(m_data.k->kff * xv) - m_data.f.dot(xv);
    return std::isfinite(obj_value);
  }

  bool eval_grad_f(Ipopt::Index n, const Ipopt::Number* x, bool, Ipopt::Number* grad_f) override {
    const Eigen::Map<const Eigen::VectorXd> xv(x, n);
    Eigen::Map<Eigen::VectorXd>(grad_f, n) = m_data.k->kff * xv - m_data.f;
    return true;
  }

  bool eval_g(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Index m, Ipopt::Number* g) override {
    std::fill(g, g + m, 0.0);
    for (size_t e = 0; e < m_data.a_val.size(); ++e) g[m_data.a_row[e]] += m_data.a_val[e] * x[m_data.a_col[e]];
    return true;
  }

  bool eval_jac_g(Ipopt::Index, const Ipopt::Number*, bool, Ipopt::Index, Ipopt::Index nele_jac, Ipopt::Index* i_row,
                  Ipopt::Index* j_col, Ipopt::Number* values) override {
    if (values == nullptr) {
      std::copy(m_data.a_row.begin(), m_data.a_row.end(), i_row);
      std::copy(m_data.a_col.begin(), m_data.a_col.end(), j_col);
    } else {
      std::copy(m_data.a_val.begin(), m_data.a_val.begin() + nele_jac, values);
    }
    return true;
  }

  // Hessian of the Lagrangian = σ K_ff (the constraints are linear); lower triangle.
  bool eval_h(Ipopt::Index, const Ipopt::Number*, bool, Ipopt::Number obj_factor, Ipopt::Index, const Ipopt::Number*,
              bool, Ipopt::Index nele_hess, Ipopt::Index* i_row, Ipopt::Index* j_col, Ipopt::Number* values) override {
    const FreeStiffness& k = *m_data.k;
    if (values == nullptr) {
      std::copy(k.h_row.begin(), k.h_row.end(), i_row);
      std::copy(k.h_col.begin(), k.h_col.end(), j_col);
    } else {
      for (Ipopt::Index e = 0; e < nele_hess; ++e) values[e] = obj_factor * k.h_val[e];
    }
    return true;
  }

  void finalize_solution(Ipopt::SolverReturn, Ipopt::Index n, const Ipopt::Number* x, const Ipopt::Number*,
                         const Ipopt::Number*, Ipopt::Index m, const Ipopt::Number*, const Ipopt::Number* lambda,
                         Ipopt::Number, const Ipopt::IpoptData* ip_data, Ipopt::IpoptCalculatedQuantities* ip_cq) override {
    m_x = Eigen::Map<const Eigen::VectorXd>(x, n);
    m_lambda = Eigen::Map<const Eigen::VectorXd>(lambda, m);
    if (ip_data) m_iterations = ip_data->iter_count();
    if (ip_cq) m_nlp_error = ip_cq->curr_nlp_error();
    m_finalized = true;
  }

  bool finalized() const { return m_finalized; }
  const Eigen::VectorXd& x() const { return m_x; }
  const Eigen::VectorXd& lambda() const { return m_lambda; }
  int iterations() const { return m_iterations; }
  /// Ipopt's (scaled) overall NLP error of the final iterate, the quantity compared with `tol`.
  double nlp_error() const { return m_nlp_error; }

 private:
  const QpData& m_data;
  Eigen::VectorXd m_x, m_lambda;
  int m_iterations = 0;
  double m_nlp_error = std::numeric_limits<double>::infinity();
  bool m_finalized = false;
};

const char* ipopt_status_name(Ipopt::ApplicationReturnStatus s) {
  switch (s) {
    case Ipopt::Solve_Succeeded: return "Solve_Succeeded";
    case Ipopt::Solved_To_Acceptable_Level: return "Solved_To_Acceptable_Level";
    case Ipopt::Infeasible_Problem_Detected: return "Infeasible_Problem_Detected";
    case Ipopt::Search_Direction_Becomes_Too_Small: return "Search_Direction_Becomes_Too_Small";
    case Ipopt::Diverging_Iterates: return "Diverging_Iterates";
    case Ipopt::User_Requested_Stop: return "User_Requested_Stop";
    case Ipopt::Feasible_Point_Found: return "Feasible_Point_Found";
    case Ipopt::Maximum_Iterations_Exceeded: return "Maximum_Iterations_Exceeded";
    case Ipopt::Restoration_Failed: return "Restoration_Failed";
    case Ipopt::Error_In_Step_Computation: return "Error_In_Step_Computation";
    case Ipopt::Maximum_CpuTime_Exceeded: return "Maximum_CpuTime_Exceeded";
    case Ipopt::Not_Enough_Degrees_Of_Freedom: return "Not_Enough_Degrees_Of_Freedom";
    case Ipopt::Invalid_Problem_Definition: return "Invalid_Problem_Definition";
    case Ipopt::Invalid_Option: return "Invalid_Option";
    case Ipopt::Invalid_Number_Detected: return "Invalid_Number_Detected";
    case Ipopt::Unrecoverable_Exception: return "Unrecoverable_Exception";
    case Ipopt::NonIpopt_Exception_Thrown: return "NonIpopt_Exception_Thrown";
    case Ipopt::Insufficient_Memory: return "Insufficient_Memory";
    case Ipopt::Internal_Error: return "Internal_Error";
  }
  return "unknown Ipopt status";
}

/// \param nlp_error Ipopt's final NLP error; a stop at a tiny step (round-off floor above
///   `tol`) counts as success when it is at most `acceptable_tol`.
Status map_status(Ipopt::ApplicationReturnStatus s, double nlp_error, double acceptable_tol) {
  switch (s) {
    case Ipopt::Solve_Succeeded:
    case Ipopt::Solved_To_Acceptable_Level: return Status::Success;
    case Ipopt::Search_Direction_Becomes_Too_Small:
      return nlp_error <= acceptable_tol ? Status::Success : Status::NumericalIssue;
    case Ipopt::Maximum_Iterations_Exceeded:
    case Ipopt::Maximum_CpuTime_Exceeded: return Status::NoConvergence;
    default: return Status::NumericalIssue;
  }
}

/// Ipopt 3.11 with the sequential MUMPS build is not known to be re-entrant (MUMPS'
/// fake MPI layer keeps global state), so concurrent solves are serialised.
std::mutex& ipopt_mutex() {
  static std::mutex m;
  return m;
}

}  // namespace

struct IpoptQpSolver::Impl {
  const fom::Problem& problem;
  IpoptOptions options;
  std::vector<int> free_index;    // full dof -> free index, -1 on Dirichlet dofs
  std::vector<int> surface_free;  // surface column -> free index, -1 on Dirichlet dofs
  std::unique_ptr<FreeStiffness> constant_k;  // set when K does not depend on μ
  double setup_time = 0.0;

  Impl(const fom::Problem& p, IpoptOptions o) : problem(p), options(o) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::vector<int>& free = problem.free_dofs();
    free_index.assign(problem.num_dofs(), -1);
    for (size_t i = 0; i < free.size(); ++i) free_index[free[i]] = static_cast<int>(i);
    for (int d : problem.contact().surface_dofs()) surface_free.push_back(free_index[d]);
    if (problem.stiffness_is_constant()) {
      const Param mid = 0.5 * (problem.param_lower() + problem.param_upper());
      constant_k = extract_free_stiffness(problem.stiffness(mid), free, free_index, problem.contact().has_pairing());
    }
    setup_time = seconds_since(t0);
  }

  /// Builds the NLP constraints A x ≤ b for the current pairing (see QpData).
  void build_constraints(const Pairing& pairing, const Eigen::VectorXd& lift_surface, QpData& qp) const {
    const fom::ContactModel& contact = problem.contact();
    ConstraintMatrix c;
    Eigen::VectorXd g;
    contact.assemble(pairing, c, g);
    const Eigen::VectorXd b_all = g - c * lift_surface;
    qp.a_row.clear();
    qp.a_col.clear();
    qp.a_val.clear();
    qp.kept_rows.clear();
    std::vector<double> b;
    for (int s = 0; s < c.rows(); ++s) {
      // Unpaired slave nodes have zero rows and can never be active: λ_s = 0. Rows that
      // touch Dirichlet dofs only are constant constraints that no free dof can change;
      // they are dropped as in the active-set solver (their gap shows in the KKT residuals).
      if (contact.has_pairing() && pairing.segment[s] < 0) continue;
      const int r = static_cast<int>(qp.kept_rows.size());
      const size_t entries = qp.a_val.size();
      for (ConstraintMatrix::InnerIterator it(c, s); it; ++it) {
        const int col = surface_free[it.col()];
        if (col < 0 || it.value() == 0.0) continue;
        qp.a_row.push_back(r);
        qp.a_col.push_back(col);
        qp.a_val.push_back(it.value());
      }
      if (qp.a_val.size() == entries) continue;
      qp.kept_rows.push_back(s);
      b.push_back(b_all(s));
    }
    qp.b = Eigen::Map<const Eigen::VectorXd>(b.data(), static_cast<Eigen::Index>(b.size()));
  }

  /// \param warm whether qp.lambda0 holds the multipliers of a nearby QP (warm start)
  void set_options(Ipopt::IpoptApplication& app, bool warm) const {
    const Ipopt::SmartPtr<Ipopt::OptionsList> o = app.Options();
    o->SetIntegerValue("print_level", options.print_level);
    o->SetStringValue("sb", "yes");
    o->SetNumericValue("tol", options.tol);
    o->SetNumericValue("acceptable_tol", options.acceptable_tol);
    o->SetNumericValue("mu_min", options.mu_min);
    o->SetIntegerValue("max_iter", options.max_iterations);
    o->SetNumericValue("bound_relax_factor", 0.0);
    o->SetStringValue("hessian_constant", "yes");
    o->SetStringValue("jac_c_constant", "yes");
    o->SetStringValue("jac_d_constant", "yes");
    o->SetStringValue("mu_strategy", "adaptive");
    o->SetStringValue("linear_solver", "mumps");
    if (warm) {
      // Start from the previous primal–dual point with the barrier parameter and the
      // interior pushes at the size of the expected change (see IpoptOptions::warm_start_push).
      o->SetStringValue("warm_start_init_point", "yes");
      o->SetNumericValue("warm_start_bound_push", options.warm_start_push);
      o->SetNumericValue("warm_start_mult_bound_push", options.warm_start_push);
      o->SetNumericValue("warm_start_slack_bound_push", options.warm_start_push);
      o->SetNumericValue("mu_init", options.warm_start_push);
    }
  }
};

IpoptQpSolver::IpoptQpSolver(const fom::Problem& problem, IpoptOptions options)
    : m_impl((fom::check_rigid_motions_held(problem), std::make_unique<Impl>(problem, options))) {}

IpoptQpSolver::~IpoptQpSolver() = default;

double IpoptQpSolver::setup_time() const { return m_impl->setup_time; }

const IpoptOptions& IpoptQpSolver::options() const { return m_impl->options; }

/// One solve at μ: the QP data and the iterate shared by the Ipopt solves of the
/// pairing fixed point (fom/pairing_fixed_point.hpp), which calls it once per pairing.
class IpoptQpSolver::Query {
 public:
  Query(const Impl& impl, const Param& mu, const FomSolution* warm)
      : m_impl(impl),
        m_problem(impl.problem),
        m_contact(impl.problem.contact()),
        m_free(impl.problem.free_dofs()),
        m_nf(static_cast<int>(m_free.size())),
        m_nc(m_contact.num_constraints()),
        m_lift(m_problem.lifting(mu)),
        m_lift_s(m_contact.restrict_to_surface(m_lift)),
        m_gap(Eigen::VectorXd::Constant(m_nc, std::numeric_limits<double>::infinity())) {
    m_sol.mu = mu;
    m_sol.lambda = Eigen::VectorXd::Zero(m_nc);
    set_up_qp(mu);
    start(warm);
  }

  /// Surface displacement that chooses the first pairing, and that pairing.
  const Eigen::VectorXd& surface_start() const { return m_surface_start; }
  const Pairing& first_pairing() const { return m_first_pairing; }

  /// One exact Ipopt solve at `pairing` (the pairing fixed point's step).
  fom::PairedSolution operator()(const Pairing& pairing, const ConstraintMatrix&, const Eigen::VectorXd&,
                                 const Eigen::VectorXd&) {
    m_impl.build_constraints(pairing, m_lift_s, m_qp);
    warm_multipliers();
    IpoptRun run = run_ipopt();
    m_sol.iterations += run.nlp->iterations();
    ++m_sol.pairing_iterations;
    const bool have_iterate = take_iterate(*run.nlp, pairing);
    fom::PairedSolution out;
    out.status = map_status(run.status, run.nlp->nlp_error(), m_impl.options.acceptable_tol);
    if (out.status != Status::Success || !have_iterate) {
      if (out.status == Status::Success) out.status = Status::NumericalIssue;
      report_failure(run);
      return out;
    }
    out.surface_displacement = m_contact.restrict_to_surface(m_u);
    out.lambda = carried_forces();
    return out;
  }

  /// The answer after the pairing fixed point: status, active rows, and the FOM
  /// check of the returned iterate.
  FomSolution finish(const fom::PairingFixedPointResult& fp, const fom::PairingFixedPointOptions& fixed_point) {
    const IpoptOptions& opt = m_impl.options;
    m_sol.status = fp.status;
    if (fp.status != Status::Success && fp.solution.status == Status::Success)  // the cap, not a failed solve
      m_sol.message = fom::pairing_no_convergence_message(fp, fixed_point);
    m_sol.u = m_u;
    m_sol.active = count_active_rows();
    // Ipopt's own success is measured in its scaled problem; a solution whose FOM KKT
    // residuals are large is not reported as one. (Complementarity is left out:
    // relative to Σ w|λ|, it is meaningless when every pressure is round-off, e.g. a
    // body pulled away from the obstacle.)
    fom::certify_fom_solution(m_problem, m_sol, opt.kkt_tolerance, false);
    const fom::KktResiduals& k = m_sol.kkt;
    if (m_sol.status != Status::Success) {
      // Report how far the returned iterate is from a KKT point (fom/kkt.hpp residuals).
      std::ostringstream msg;
      msg.precision(3);
      msg << "; KKT residuals of the returned iterate: stationarity " << k.stationarity << ", penetration "
          << k.penetration << ", negative pressure " << k.negative_pressure << ", complementarity "
          << k.complementarity;
      m_sol.message += msg.str();
    }
    return std::move(m_sol);
  }

 private:
  struct IpoptRun {
    Ipopt::SmartPtr<ContactQpNlp> nlp;
    Ipopt::ApplicationReturnStatus status = Ipopt::Internal_Error;
    std::string error;
  };

  /// K_ff (the offline one when K does not depend on μ) and f_f.
  void set_up_qp(const Param& mu) {
    if (!m_impl.constant_k)
      m_own_k = extract_free_stiffness(m_problem.stiffness(mu), m_free, m_impl.free_index, m_contact.has_pairing());
    m_qp.k = m_impl.constant_k ? m_impl.constant_k.get() : m_own_k.get();
    const Eigen::VectorXd f = m_problem.rhs(mu);
    m_qp.f.resize(m_nf);
    for (int i = 0; i < m_nf; ++i) m_qp.f(i) = f(m_free[i]);
  }

  /// Starting point and the configuration that seeds the pairing: the warm solution
  /// if it fits, else (as in the active-set solver) the unconstrained solution, else
  /// u0 = 0. The pairing fixed point is not globally convergent: started from the
  /// reference configuration, `ironing` falls into a 2-cycle.
  void start(const FomSolution* warm) {
    const bool warm_fits = warm && warm->u.size() == m_problem.num_dofs() && warm->lambda.size() == m_nc &&
                           warm->u.allFinite() && warm->lambda.allFinite();
    m_qp.x0 = Eigen::VectorXd::Zero(m_nf);
    if (warm_fits) {
      for (int i = 0; i < m_nf; ++i) m_qp.x0(i) = warm->u(m_free[i]) - m_lift(m_free[i]);
    } else if (m_qp.k->ldlt && m_qp.k->ldlt->info() == Eigen::Success) {
      const Eigen::VectorXd x = m_qp.k->ldlt->solve(m_qp.f);
      if (x.allFinite()) m_qp.x0 = x;
    }
    set_displacement();
    // The surface displacement that chooses the pairing (Anderson-extrapolated by
    // the fixed point).
    m_surface_start = m_contact.restrict_to_surface(m_u);
    m_first_pairing = (warm_fits && warm->pairing.segment.size() == static_cast<size_t>(m_nc))
                          ? warm->pairing
                          : m_contact.search(m_surface_start);
    if (warm_fits) m_sol.lambda = warm->lambda;
    m_have_multipliers = warm_fits;
  }

  /// u = u_lift + x on the free dofs.
  void set_displacement() {
    m_u = m_lift;
    for (int i = 0; i < m_nf; ++i) m_u(m_free[i]) += m_qp.x0(i);
  }

  /// The last multipliers of the kept rows, when warm starts are on.
  void warm_multipliers() {
    m_qp.lambda0.resize(0);
    if (!m_impl.options.warm_start || !m_have_multipliers || m_qp.kept_rows.empty()) return;
    m_qp.lambda0.resize(static_cast<Eigen::Index>(m_qp.kept_rows.size()));
    for (size_t r = 0; r < m_qp.kept_rows.size(); ++r) m_qp.lambda0(r) = m_sol.lambda(m_qp.kept_rows[r]);
  }

  /// Ipopt on the current QP (one process-wide lock: Ipopt's MUMPS is not reentrant).
  IpoptRun run_ipopt() const {
    IpoptRun run;
    // Ipopt's own reference-counted smart pointer requires heap allocation by `new`.
    run.nlp = new ContactQpNlp(m_qp);
    try {
      std::lock_guard<std::mutex> lock(ipopt_mutex());
      Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
      m_impl.set_options(*app, m_qp.lambda0.size() > 0);
      run.status = app->Initialize("");  // "": never read an ipopt.opt from the working directory
      if (run.status == Ipopt::Solve_Succeeded) run.status = app->OptimizeTNLP(Ipopt::GetRawPtr(run.nlp));
    } catch (const std::exception& e) {
      run.error = e.what();
      run.status = Ipopt::NonIpopt_Exception_Thrown;
    } catch (...) {
      run.error = "unknown exception";
      run.status = Ipopt::Unrecoverable_Exception;
    }
    return run;
  }

  /// Takes Ipopt's iterate, if it has a finite one: x, the multipliers, u, the
  /// pairing of the constraint operator λ was solved with, and the gaps.
  bool take_iterate(const ContactQpNlp& nlp, const Pairing& pairing) {
    const bool have_iterate = nlp.finalized() && nlp.x().size() == m_nf && nlp.lambda().size() == m_qp.b.size() &&
                              nlp.x().allFinite() && nlp.lambda().allFinite();
    if (!have_iterate) return false;
    // Ipopt's Lagrangian is f + λᵀ g(x): for g(x) ≤ g_u its multipliers are ≥ 0 and
    // K_ff x − f_f + Aᵀ λ = 0, the sign convention of the contact pressures.
    m_qp.x0 = nlp.x();
    m_sol.lambda.setZero();
    for (size_t r = 0; r < m_qp.kept_rows.size(); ++r) m_sol.lambda(m_qp.kept_rows[r]) = nlp.lambda()(r);
    m_have_multipliers = true;
    set_displacement();
    m_sol.pairing = pairing;
    // Gaps (length units) of the kept rows under that operator: b − A x, per tributary length.
    m_gap.setConstant(std::numeric_limits<double>::infinity());
    Eigen::VectorXd ax = Eigen::VectorXd::Zero(m_qp.b.size());
    for (size_t e = 0; e < m_qp.a_val.size(); ++e) ax(m_qp.a_row[e]) += m_qp.a_val[e] * m_qp.x0(m_qp.a_col[e]);
    for (size_t r = 0; r < m_qp.kept_rows.size(); ++r) {
      const int s = m_qp.kept_rows[r];
      m_gap(s) = (m_qp.b(r) - ax(r)) / m_contact.weights()(s);
    }
    return true;
  }

  void report_failure(const IpoptRun& run) {
    std::ostringstream msg;
    msg << "Ipopt returned " << ipopt_status_name(run.status) << " after " << run.nlp->iterations()
        << " iterations in pairing iteration " << m_sol.pairing_iterations;
    if (!run.error.empty()) msg << " (" << run.error << ")";
    m_sol.message = msg.str();
  }

  /// The pressures the stopping test reads: the rows that carry force (an
  /// interior-point method leaves multipliers ≈ barrier parameter / slack on the others).
  Eigen::VectorXd carried_forces() const {
    Eigen::VectorXd lambda = m_sol.lambda;
    const double lmax = m_sol.lambda.size() ? m_sol.lambda.maxCoeff() : 0.0;
    for (int s = 0; s < m_nc; ++s)
      if (!(m_sol.lambda(s) > m_impl.options.active_tolerance * lmax)) lambda(s) = 0.0;
    return lambda;
  }

  /// Interior-point multipliers are never exactly zero: a row is active when its
  /// pressure is significant (relative to the largest) and it touches (gap relative
  /// to the displacement scale), both to active_tolerance.
  int count_active_rows() const {
    const double tol = m_impl.options.active_tolerance;
    const double lmax = m_sol.lambda.size() ? m_sol.lambda.maxCoeff() : 0.0;
    const double gap_tol = tol * m_problem.displacement_scale();
    int active = 0;
    for (int s = 0; s < m_nc; ++s)
      if (m_sol.lambda(s) > tol * lmax && m_gap(s) <= gap_tol) ++active;
    return active;
  }

  const Impl& m_impl;
  const fom::Problem& m_problem;
  const fom::ContactModel& m_contact;
  const std::vector<int>& m_free;
  const int m_nf, m_nc;
  const Eigen::VectorXd m_lift, m_lift_s;
  std::unique_ptr<FreeStiffness> m_own_k;  // K_ff at μ when K depends on μ
  QpData m_qp;
  FomSolution m_sol;
  Eigen::VectorXd m_u;  // the current iterate
  Eigen::VectorXd m_gap;  // gaps of the last iterate (∞ off the kept rows)
  Eigen::VectorXd m_surface_start;
  Pairing m_first_pairing;
  bool m_have_multipliers = false;
};

FomSolution IpoptQpSolver::solve(const Param& mu, const FomSolution* warm) const {
  m_impl->problem.check_param(mu);
  const auto t0 = std::chrono::steady_clock::now();
  const IpoptOptions& opt = m_impl->options;
  Query query(*m_impl, mu, warm);
  // One exact Ipopt solve per pairing; the shared pairing fixed point re-pairs,
  // accelerates and decides when to stop.
  fom::PairingFixedPointOptions fixed_point;
  fixed_point.max_iterations = opt.max_pairing_iterations;
  fixed_point.tolerance = opt.pairing_tolerance;
  fixed_point.anderson_depth = opt.anderson_depth;
  const fom::PairingFixedPointResult fp =
      fom::solve_pairing_fixed_point(m_impl->problem.contact(), m_impl->problem.displacement_scale(),
                                     query.surface_start(), query.first_pairing(), fixed_point, query);
  FomSolution sol = query.finish(fp, fixed_point);
  sol.time_s = seconds_since(t0);
  return sol;
}

std::unique_ptr<fom::FullOrderSolver> make_fom_solver(const fom::Problem& problem, const std::string& name) {
  if (name == "active-set") return std::make_unique<fom::ActiveSetSolver>(problem);
  if (name == "ipopt") return std::make_unique<IpoptQpSolver>(problem);
  throw InputError("solver " + quoted(name, 200) + " unknown; expected active-set or ipopt");
}

}  // namespace contactrom::baselines
