#pragma once
/// \file problem.hpp
/// \brief A parametrised linear-elastic contact problem, built from a problem
/// file (fom/problem_file.hpp) and its mesh, or the 1D `rope` written in C++
/// (fom/rope.hpp).
///
/// Discrete problem (paper eq. 1–2), in full dof numbering with Dirichlet dofs
/// kept: \f$ u = u_{lift}(\mu) + u_0 \f$ with \f$ u_0 = 0 \f$ on Dirichlet dofs and
/// \f[ \min_{u_0} \tfrac12 u_0^T K(\mu) u_0 - u_0^T f(\mu) \quad\text{s.t.}\quad
///     C(u)\,u - g(u) \le 0, \f]
/// where \f$ f(\mu) = f_{ext}(\mu) - K(\mu) u_{lift}(\mu) \f$ (zero on Dirichlet rows).
/// Both \f$ K \f$ and \f$ f \f$ are affine in the parameters:
/// \f$ K(\mu) = \sum_q \theta_q(\mu) K_q \f$, \f$ f_{ext}(\mu) = \sum_k \phi_k(\mu) f_k \f$,
/// \f$ u_{lift}(\mu) = \sum_k \phi_k(\mu) L_k \f$, with θ and φ affine functions. When
/// no Young's modulus depends on a parameter K is constant: it is factorised once and
/// reused for every parameter.
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <memory>
#include <string>
#include <vector>

#include <contactrom/core/parallel_for.hpp>
#include <contactrom/fom/contact_model.hpp>
#include <contactrom/fom/elasticity.hpp>
#include <contactrom/fom/mesh.hpp>
#include <contactrom/fom/parameter_space.hpp>
#include <contactrom/fom/problem_file.hpp>

namespace contactrom::fom {

/// \brief Options of make_problem (documented defaults).
struct ProblemOptions {
  /// Extra uniform refinements on top of the file's `refine` (`--refine k`), default 0.
  /// Not used by `rope` (fom/rope.hpp has its own options).
  int refine = 0;
  /// Called from the calling thread about every 0.1 s while gmsh meshes the problem's
  /// `.geo` or `.msh` file, with (0, 1) (MeshOptions::progress); an exception it throws
  /// stops meshing (gmsh's process is killed) and propagates. Optional; the Python
  /// module's Ctrl-C check.
  ProgressCallback progress;
};

/// \brief What a Problem is made of, as a builder fills it: build_problem() from a
/// problem file and its mesh, make_rope_problem() (fom/rope.hpp) in C++. Sizes: n dofs,
/// Q stiffness terms, T load terms.
struct ProblemParts {
  ProblemDefinition definition;             ///< the problem file read into data (rope: its equivalent)
  int dofs_per_node = 2;                    ///< 2 or 3 (the mesh's dimension), 1 for a 1D problem
  std::vector<char> is_dirichlet;           ///< n flags
  std::vector<SparseMatrix> stiffness_terms;        ///< K_q, Q matrices n × n
  std::vector<AffineExpression> stiffness_coefficients;  ///< θ_q(μ), Q
  std::vector<Eigen::VectorXd> lifting_terms;       ///< L_k, T vectors of size n (Dirichlet values)
  std::vector<Eigen::VectorXd> external_load_terms; ///< f_ext,k, T vectors of size n
  std::vector<AffineExpression> load_coefficients;  ///< φ_k(μ), T
  std::unique_ptr<ContactModel> contact;    ///< the contact constraints (required)
  SparseMatrix h1_gram;                     ///< n × n Gram matrix of the H¹ norm
  std::unique_ptr<Mesh> mesh;               ///< the mesh; nullptr for a 1D problem
  std::string fingerprint;                  ///< of the discretisation
  double displacement_scale = 1.0;          ///< U (> 0)
};

/// \brief A parametrised linear-elastic contact problem; see the file comment.
/// All of it is data: the affine terms, the contact model, the mesh and the
/// definition it was built from (sampling plans and ROM settings live there).
class Problem {
 public:
  /// \brief Takes the parts over. \throws std::invalid_argument if their sizes do not
  /// agree (a builder's error, not the user's).
  explicit Problem(ProblemParts parts);

  const std::string& name() const { return m_definition.name; }
  /// The problem file read into data (for `rope`, the equivalent built in C++).
  const ProblemDefinition& definition() const { return m_definition; }
  const ParameterSpace& parameters() const { return m_definition.parameters; }
  int num_params() const { return parameters().size(); }
  const std::vector<std::string>& param_names() const { return parameters().names; }
  const Eigen::VectorXd& param_lower() const { return parameters().lower; }
  const Eigen::VectorXd& param_upper() const { return parameters().upper; }
  /// \throws InputError naming the value and the expected range.
  void check_param(const Param& mu) const { parameters().check(mu, name()); }
  /// Human-readable range, e.g. "d in (0, 0.3]".
  std::string range_text() const { return parameters().range_text(); }

  int num_dofs() const { return static_cast<int>(m_is_dirichlet.size()); }
  /// Spatial dimension of a node's displacement (2 or 3 = the mesh's dimension, 1 for rope).
  int dofs_per_node() const { return m_dofs_per_node; }
  const std::vector<char>& is_dirichlet() const { return m_is_dirichlet; }
  /// Indices of the free dofs, ascending.
  const std::vector<int>& free_dofs() const { return m_free_dofs; }

  int num_stiffness_terms() const { return static_cast<int>(m_k_terms.size()); }
  const SparseMatrix& stiffness_term(int q) const { return m_k_terms[q]; }
  /// θ_q(μ) of K(μ) = Σ θ_q K_q.
  Eigen::VectorXd stiffness_coefficients(const Param& mu) const;
  /// K(μ) on all dofs (Dirichlet rows/columns kept).
  SparseMatrix stiffness(const Param& mu) const;
  /// \brief K(μ) v = Σ θ_q(μ) (K_q v) on all dofs, without forming K(μ) (a per-query
  /// residual must not copy the matrix: at 2k dofs that copy costs more than the solve).
  Eigen::VectorXd apply_stiffness(const Param& mu, const Eigen::VectorXd& v) const;
  bool stiffness_is_constant() const { return m_k_terms.size() == 1 && m_k_coeff[0].is_constant(); }

  int num_load_terms() const { return static_cast<int>(m_lift_terms.size()); }
  /// Coefficients φ_k(μ) of the affine load/lifting.
  Eigen::VectorXd load_coefficients(const Param& mu) const;
  /// Lifting basis vectors L_k (Dirichlet values; zero elsewhere).
  const std::vector<Eigen::VectorXd>& lifting_terms() const { return m_lift_terms; }
  /// External load basis f_ext,k (same coefficients as the lifting).
  const std::vector<Eigen::VectorXd>& external_load_terms() const { return m_fext_terms; }
  Eigen::VectorXd lifting(const Param& mu) const;
  /// f(μ) = f_ext(μ) − K(μ) u_lift(μ), zeroed on Dirichlet rows.
  Eigen::VectorXd rhs(const Param& mu) const;

  const ContactModel& contact() const { return *m_contact; }
  /// Gram matrix of the H¹ norm used for primal errors.
  const SparseMatrix& h1_gram() const { return m_h1; }
  /// The mesh, 2D or 3D (nullptr for the 1D rope).
  const Mesh* mesh() const { return m_mesh.get(); }
  /// Material of each body at μ (Young's moduli evaluated).
  std::vector<Material> materials(const Param& mu) const;
  /// Fingerprint of the discretisation (problem definition + mesh).
  std::string fingerprint() const { return m_fingerprint; }
  /// Scale of the displacement field (max |Dirichlet value| over the range, or the
  /// file's `displacement_scale`), used to make penetration and complementarity
  /// residuals relative.
  double displacement_scale() const { return m_u_scale; }

 private:
  void check_sizes() const;  // of the parts taken over

  ProblemDefinition m_definition;
  int m_dofs_per_node = 2;
  std::vector<char> m_is_dirichlet;
  std::vector<int> m_free_dofs;
  std::vector<SparseMatrix> m_k_terms;
  std::vector<AffineExpression> m_k_coeff, m_load_coeff;
  std::vector<Eigen::VectorXd> m_lift_terms, m_fext_terms;
  /// K_q times the lifting terms (n x T per stiffness term q), for rhs() without a
  /// product with K per call.
  std::vector<Eigen::MatrixXd> m_k_lift;
  std::unique_ptr<ContactModel> m_contact;
  SparseMatrix m_h1;
  std::unique_ptr<Mesh> m_mesh;
  std::string m_fingerprint;
  double m_u_scale = 1.0;
};

/// \brief The fingerprint of a text, 16 lower-case hex digits (a 64-bit FNV-1a-style
/// hash): what Problem::fingerprint() is made of, stored by databases and reduced-model
/// files to refuse a problem they were not built for.
std::string text_fingerprint(const std::string& text);

/// \brief One prescribed displacement component of a problem file's `[[dirichlet]]`
/// entries and its largest magnitude over the parameter box.
struct PrescribedDisplacement {
  std::string group;
  int component = 0;       ///< 0, 1, 2: x, y, z
  double magnitude = 0.0;  ///< max |value| over the box
};

/// \brief Every prescribed (not free) Dirichlet component of `def`, in file order:
/// what the default displacement scale U is the largest of.
std::vector<PrescribedDisplacement> prescribed_displacements(const ProblemDefinition& def);

/// \brief The free-dof block K_ff of a matrix on all dofs (Dirichlet rows and columns
/// dropped). \param free_index position of each dof among the free dofs (−1: Dirichlet)
/// \param num_free number of free dofs
SparseMatrix free_block(const SparseMatrix& k, const std::vector<int>& free_index, int num_free);

/// \brief Builds a problem from a definition and its (already loaded) mesh; no gmsh.
/// Checks the definition against the mesh: every physical surface has a body, every
/// group named exists, slave curves lie on the boundary of their body, Dirichlet
/// values agree where groups meet.
/// \throws InputError naming the problem file, line and key.
std::unique_ptr<Problem> build_problem(ProblemDefinition definition, Mesh mesh);

/// \brief `--problem`: "rope" (make_rope_problem() with its defaults), a shipped name ("hertz" → problems/hertz.toml) or a
/// problem file path; reads the file, meshes it with gmsh (refined as asked) and
/// builds the problem. \throws InputError for an unknown name or a bad file or mesh.
std::unique_ptr<Problem> make_problem(const std::string& name_or_path, const ProblemOptions& options = {});

/// \brief The training set of size or level `n` given by the problem's `[training]` plan.
/// \throws InputError for an `n` out of range for the plan.
std::vector<Param> training_set(const Problem& problem, int n);
/// \brief The validation set associated with training size or level `n` (`[validation]`).
std::vector<Param> validation_set(const Problem& problem, int n);

/// \brief Parses "V" or "V1,V2" into a parameter for `problem` and checks its range.
Param parse_param(const Problem& problem, const std::string& text);

}  // namespace contactrom::fom
