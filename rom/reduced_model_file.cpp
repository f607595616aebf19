#include <contactrom/rom/reduced_model_file.hpp>

#include <hdf5.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <contactrom/core/format.hpp>
#include <contactrom/core/atomic_file.hpp>
#include <contactrom/core/errors.hpp>
#include <contactrom/core/input_file.hpp>
#include <contactrom/core/version.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/rom/dense_csv.hpp>
#include <contactrom/rom/fallback.hpp>
#include <contactrom/rom/hdf5_io.hpp>
#include <contactrom/rom/online_methods.hpp>
#include <contactrom/rom/problem_record_io.hpp>

namespace contactrom::rom {
namespace {

using hdf5::Handle;

/// The column-major rows × cols matrix as a dataset of cols rows (one column of
/// `m` per dataset row, as h5py users index them).
void write_columns(hid_t f, hid_t dcpl, const char* name, const Eigen::MatrixXd& m) {
  hdf5::write_dataset(f, dcpl, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, static_cast<hsize_t>(m.cols()),
                      static_cast<hsize_t>(m.rows()), m.data());
}

/// Shape (rows, cols) of a rank-2 dataset. \throws hdf5::Refused for another rank.
std::pair<hsize_t, hsize_t> shape2(hid_t f, const char* name) {
  const std::vector<hsize_t> dims = hdf5::dataset_shape(f, name);
  if (dims.size() != 2) throw hdf5::Refused(std::string("dataset /") + name + " is not two-dimensional");
  return {dims[0], dims[1]};
}

/// Reads what write_columns wrote: a dataset of `cols` rows of `rows` finite numbers.
Eigen::MatrixXd read_columns(hid_t f, const char* name, hsize_t rows, hsize_t cols) {
  const auto [r, c] = shape2(f, name);
  if (r != cols || c != rows)
    throw hdf5::Refused(std::string("dataset /") + name + " has shape (" + std::to_string(r) + ", " +
                        std::to_string(c) + "), expected (" + std::to_string(cols) + ", " + std::to_string(rows) + ")");
  std::vector<double> buf;
  hsize_t a = 0, b = 0;
  hdf5::read_double_dataset(f, name, buf, a, b);
  for (double v : buf)
    if (!std::isfinite(v)) throw hdf5::Refused(std::string("dataset /") + name + " holds a non-finite number");
  return Eigen::Map<Eigen::MatrixXd>(buf.data(), static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(cols));
}

std::string offset_name(OffsetKind kind) { return kind == OffsetKind::Dirichlet ? "dirichlet" : "harmonic"; }

/// The attribute `offset` (named `lifting` before format version 3).
OffsetKind read_offset_kind(hid_t f) {
  const char* name = hdf5::has_attribute(f, "offset") ? "offset" : "lifting";
  const std::string kind = hdf5::read_string_attribute(f, name);
  if (kind != "harmonic" && kind != "dirichlet")
    throw hdf5::Refused(std::string("attribute ") + name + " is " + quoted(kind, 200) + ", expected 'harmonic' or 'dirichlet'");
  return kind == "dirichlet" ? OffsetKind::Dirichlet : OffsetKind::Harmonic;
}

void write_model(hid_t f, hid_t dcpl, const OnlineModel& rom) {
  const ReducedModelData d = rom.model().data();
  const int version = kReducedModelFormatVersion;
  hdf5::write_string_attribute(f, "kind", kReducedModelKind);
  hdf5::write_scalar_attribute(f, "format_version", H5T_STD_I32LE, H5T_NATIVE_INT, &version);
  hdf5::write_string_attribute(f, "created_by", "contactrom " + contactrom::version());
  hdf5::write_string_attribute(f, "method", rom.method());
  hdf5::write_scalar_attribute(f, "delta", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &d.options.delta);
  hdf5::write_string_attribute(f, "offset", offset_name(d.options.offset));
  const int include_failed = d.options.include_failed_snapshots ? 1 : 0;
  hdf5::write_scalar_attribute(f, "include_failed_snapshots", H5T_STD_I32LE, H5T_NATIVE_INT, &include_failed);
  std::vector<std::string> keys, values;
  for (const auto& [key, value] : options_to_map(rom.method(), rom.options())) keys.push_back(key), values.push_back(value);
  Handle options(H5Gcreate2(f, "options", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose, "group /options");
  hdf5::write_string_list(f, dcpl, "options/keys", keys);
  hdf5::write_string_list(f, dcpl, "options/values", values);

  write_columns(f, dcpl, "basis", d.basis);
  write_columns(f, dcpl, "surface_basis", rom.model().surface_basis());
  const std::vector<int>& surf = rom.problem().contact().surface_dofs();
  hdf5::write_dataset(f, dcpl, "surface_dofs", H5T_STD_I32LE, H5T_NATIVE_INT, 1, surf.size(), 0, surf.data());
  hdf5::write_dataset(f, dcpl, "singular_values", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 1,
                      static_cast<hsize_t>(d.singular_values.size()), 0, d.singular_values.data());
  Eigen::MatrixXd offset(rom.problem().num_dofs(), static_cast<Eigen::Index>(d.offset_terms.size()));
  for (size_t k = 0; k < d.offset_terms.size(); ++k) offset.col(static_cast<Eigen::Index>(k)) = d.offset_terms[k];
  write_columns(f, dcpl, "offset", offset);
  Handle reduced(H5Gcreate2(f, "reduced", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose, "group /reduced");
  write_columns(f, dcpl, "reduced/load", d.load_terms);
  for (size_t q = 0; q < d.stiffness_terms.size(); ++q) {
    write_columns(f, dcpl, ("reduced/stiffness_" + std::to_string(q)).c_str(), d.stiffness_terms[q]);
    write_columns(f, dcpl, ("reduced/stiffness_offset_" + std::to_string(q)).c_str(), d.stiffness_offset_terms[q]);
  }
  write_columns(f, dcpl, "dictionary", d.dictionary);
  hdf5::write_dataset(f, dcpl, "dictionary_snapshots", H5T_STD_I32LE, H5T_NATIVE_INT, 1,
                      d.dictionary_snapshots.size(), 0, d.dictionary_snapshots.data());
  Eigen::MatrixXd params(rom.problem().num_params(), static_cast<Eigen::Index>(d.dictionary_parameters.size()));
  for (size_t c = 0; c < d.dictionary_parameters.size(); ++c)
    params.col(static_cast<Eigen::Index>(c)) = d.dictionary_parameters[c];
  write_columns(f, dcpl, "dictionary_parameters", params);
  write_columns(f, dcpl, "snapshot_coordinates", d.snapshot_coordinates);
  // The primal snapshots (n × m, most of the file) only for a method that combines them.
  if (d.primal_snapshots.cols() > 0) write_columns(f, dcpl, "primal_snapshots", d.primal_snapshots);
  write_problem_record(f, dcpl, record_problem(rom.problem()));
}

/// What a reduced-model file holds, as read (OnlineModel::load).
struct StoredModel {
  int version = 0;
  ReducedModelData data;
  ProblemRecord record;
  std::string method;
  std::map<std::string, std::string> option_values;
};

/// The attributes: format version, method, δ, offset kind, failed snapshots, options.
void read_settings(hid_t f, const std::string& label, StoredModel& s) {
  if (!hdf5::has_attribute(f, "kind") || hdf5::read_string_attribute(f, "kind") != kReducedModelKind)
    throw InputError(label + " is not a contactrom reduced model (attribute kind is not '" + kReducedModelKind +
                     "'; a snapshot database is read with --db, not --rom)");
  s.version = hdf5::read_int_attribute(f, "format_version");
  if (s.version < 1 || s.version > kReducedModelFormatVersion)
    throw InputError(label + " has format_version " + std::to_string(s.version) + ", but this contactrom reads versions 1 to " +
                     std::to_string(kReducedModelFormatVersion) + "; rebuild it with contactrom reduce");
  s.method = hdf5::read_string_attribute(f, "method");
  ReducedModelOptions& o = s.data.options;
  o.delta = hdf5::read_double_attribute(f, "delta");
  if (!(o.delta >= 0.0 && o.delta <= 1.0))
    throw hdf5::Refused("attribute delta is " + format_number(o.delta) + ", expected a number in [0, 1]");
  o.offset = read_offset_kind(f);
  o.include_failed_snapshots = hdf5::read_int_attribute(f, "include_failed_snapshots") != 0;
  const std::vector<std::string> keys = hdf5::read_string_list(f, "options/keys", hdf5::file_size(f));
  const std::vector<std::string> values = hdf5::read_string_list(f, "options/values", hdf5::file_size(f));
  if (keys.size() != values.size()) throw hdf5::Refused("datasets /options/keys and /options/values differ in length");
  for (size_t i = 0; i < keys.size(); ++i) s.option_values[keys[i]] = values[i];
}

/// Basis, singular values, offset terms and the reduced operators (n dofs).
void read_operators(hid_t f, hsize_t n, ReducedModelData& d) {
  const auto [r, n_basis] = shape2(f, "basis");
  d.basis = read_columns(f, "basis", n, r);
  std::vector<double> sigma;
  hsize_t rows = 0, cols = 0;
  hdf5::read_double_dataset(f, "singular_values", sigma, rows, cols);
  if (cols != 1 || rows < r) throw hdf5::Refused("dataset /singular_values holds fewer values than modes");
  for (double v : sigma)
    if (!std::isfinite(v) || v < 0.0)
      throw hdf5::Refused("dataset /singular_values holds " + format_number(v) + ", expected finite values >= 0");
  d.singular_values = Eigen::Map<Eigen::VectorXd>(sigma.data(), static_cast<Eigen::Index>(rows));
  const auto [nt, n_offset] = shape2(f, "offset");
  const Eigen::MatrixXd offset = read_columns(f, "offset", n, nt);
  for (hsize_t k = 0; k < nt; ++k) d.offset_terms.push_back(offset.col(static_cast<Eigen::Index>(k)));
  d.load_terms = read_columns(f, "reduced/load", r, nt);
  for (int q = 0;; ++q) {
    const std::string name = "reduced/stiffness_" + std::to_string(q);
    if (H5Lexists(f, name.c_str(), H5P_DEFAULT) <= 0) break;
    d.stiffness_terms.push_back(read_columns(f, name.c_str(), r, r));
    d.stiffness_offset_terms.push_back(read_columns(f, ("reduced/stiffness_offset_" + std::to_string(q)).c_str(), r, nt));
  }
  (void)n_basis, (void)n_offset;
}

/// The dictionary, its columns' snapshots and parameters, their coordinates and (for
/// a method that combines them, or version 1) their primal snapshots; m columns.
void read_columns_data(hid_t f, const StoredModel& s, hsize_t n, ReducedModelData& d) {
  const hsize_t m = static_cast<hsize_t>(d.dictionary.cols()), r = static_cast<hsize_t>(d.basis.cols());
  hsize_t rows = 0, cols = 0;
  hdf5::read_int_dataset(f, "dictionary_snapshots", d.dictionary_snapshots, rows, cols);
  if (rows != m || cols != 1) throw hdf5::Refused("dataset /dictionary_snapshots does not hold one index per column");
  for (size_t c = 0; c < d.dictionary_snapshots.size(); ++c) {
    const int j = d.dictionary_snapshots[c];
    if (j < 0) throw hdf5::Refused("dataset /dictionary_snapshots holds the negative index " + std::to_string(j));
    // The columns are the kept snapshots in database order.
    if (c > 0 && j <= d.dictionary_snapshots[c - 1])
      throw hdf5::Refused("dataset /dictionary_snapshots is not increasing (" +
                          std::to_string(d.dictionary_snapshots[c - 1]) + " then " + std::to_string(j) +
                          "), expected the database order of the columns");
  }
  const auto [mp, np] = shape2(f, "dictionary_parameters");
  const Eigen::MatrixXd params = read_columns(f, "dictionary_parameters", np, m);
  for (hsize_t c = 0; c < m; ++c) d.dictionary_parameters.push_back(params.col(static_cast<Eigen::Index>(c)));
  // Version 1 stored the primal snapshots always and no coordinates; versions 2 and 3
  // the coordinates always and the snapshots only for a method that needs them.
  bool needs_primal = false;
  try {
    needs_primal = online_method_needs_primal_snapshots(s.method);
  } catch (const InputError&) {  // an unknown method is reported later, naming the file
  }
  if (s.version == 1 || needs_primal) d.primal_snapshots = read_columns(f, "primal_snapshots", n, m);
  if (s.version == 1) {
    d.snapshot_coordinates = d.basis.transpose() * d.primal_snapshots;  // stored from the offset, u − u_off
    if (!needs_primal) d.primal_snapshots.resize(0, 0);
  } else {
    d.snapshot_coordinates = read_columns(f, "snapshot_coordinates", r, m);
  }
  (void)mp;
}

/// The whole file but the problem's rebuild (OnlineModel::load).
StoredModel read_stored_model(hid_t f, const std::string& label) {
  StoredModel s;
  read_settings(f, label, s);
  const auto [r, n] = shape2(f, "basis");
  const auto [m, nc] = shape2(f, "dictionary");
  read_operators(f, n, s.data);
  s.data.dictionary = read_columns(f, "dictionary", nc, m);
  read_columns_data(f, s, n, s.data);
  const double scale = std::max(1.0, s.data.dictionary.size() ? s.data.dictionary.cwiseAbs().maxCoeff() : 0.0);
  if (s.data.dictionary.size() && s.data.dictionary.minCoeff() < -1e-9 * scale)
    throw hdf5::Refused("dataset /dictionary holds a negative pressure");
  s.record = read_problem_record(f, nc, n);
  // The surface rows are stored for readers of the file; the model takes them from the basis.
  const auto [r_s, n_s] = shape2(f, "surface_basis");
  if (r_s != r) throw hdf5::Refused("dataset /surface_basis does not hold one row per mode");
  read_columns(f, "surface_basis", n_s, r);  // its numbers are finite, as every stored number
  return s;
}

/// Versions 1 and 2 stored the primal snapshots measured from the offset, u − u_off;
/// the model holds them as the database does, u − u_lift = (u − u_off) + Σ_k φ_k (L̃_k − L_k).
void measure_primal_from_lifting(const fom::Problem& problem, ReducedModelData& d) {
  if (d.primal_snapshots.cols() == 0 || d.offset_terms.size() != static_cast<size_t>(problem.num_load_terms())) return;
  for (Eigen::Index c = 0; c < d.primal_snapshots.cols(); ++c) {
    const Eigen::VectorXd phi = problem.load_coefficients(d.dictionary_parameters[static_cast<size_t>(c)]);
    for (size_t k = 0; k < d.offset_terms.size(); ++k)
      if (d.offset_terms[k].size() == d.primal_snapshots.rows())
        d.primal_snapshots.col(c) += phi(static_cast<Eigen::Index>(k)) * (d.offset_terms[k] - problem.lifting_terms()[k]);
  }
}

}  // namespace

OnlineModel::OnlineModel(std::shared_ptr<const fom::Problem> problem, std::unique_ptr<ReducedModel> model,
                         const std::string& method, const OnlineSolverOptions& options)
    : m_problem(std::move(problem)), m_model(std::move(model)), m_method(method), m_options(options) {
  if (!m_problem) throw InputError("OnlineModel: the problem is null; expected a problem");
  if (!m_model) throw InputError("OnlineModel: the reduced model is null; expected a model");
  m_solver = make_online_solver(m_method, *m_model, m_options);
}

OnlineModel::OnlineModel(std::shared_ptr<const fom::Problem> problem, const SnapshotDatabase& db,
                         const ReducedModelOptions& model_options, const std::string& method,
                         const OnlineSolverOptions& options)
    : m_problem(std::move(problem)), m_method(method), m_options(options) {
  if (!m_problem) throw InputError("OnlineModel: the problem is null; expected a problem");
  // The method name first: building the model costs a POD.
  check_online_method(method);
  ReducedModelOptions kept = model_options;
  kept.keep_primal_snapshots = online_method_needs_primal_snapshots(method);
  m_model = std::make_unique<ReducedModel>(*m_problem, db, kept);
  m_solver = make_online_solver(m_method, *m_model, m_options);
}

OnlineResult OnlineModel::solve(const fom::Param& mu) const { return m_solver->solve(mu); }

void OnlineModel::save(const std::string& path) const {
  try {
    hdf5::write_file(path, [this](hid_t f, hid_t dcpl) { write_model(f, dcpl, *this); });
  } catch (const hdf5::Failure& e) {
    throw InputError("cannot write reduced model " + quoted(path, 200) + ": HDF5 failed on " + e.what());
  }
}

OnlineModel OnlineModel::load(const std::string& path) {
  const std::string label = "reduced model " + quoted(path, 200);
  Handle file(hdf5::open_file(path, "reduced model", "contactrom reduce"), H5Fclose, "the file structure");
  StoredModel stored;
  try {
    stored = read_stored_model(file.id(), label);
    file.close("file close");
  } catch (const hdf5::Refused& e) {
    throw InputError(label + " is not a valid contactrom reduced model: " + e.what());
  } catch (const hdf5::Failure& e) {
    throw InputError(label + " is truncated or corrupt (HDF5 cannot read " + e.what() + ")");
  }
  std::shared_ptr<const fom::Problem> problem = rebuild_problem(stored.record, label);
  for (const fom::Param& p : stored.data.dictionary_parameters) {
    try {
      problem->check_param(p);
    } catch (const InputError& e) {
      throw InputError(label + " dataset /dictionary_parameters: " + e.what());
    }
  }
  if (stored.version < 3) measure_primal_from_lifting(*problem, stored.data);
  try {
    auto model = std::make_unique<ReducedModel>(*problem, std::move(stored.data));
    return OnlineModel(problem, std::move(model), stored.method, options_from_map(stored.method, stored.option_values));
  } catch (const InputError& e) {
    throw InputError(label + ": " + e.what());
  }
}

std::vector<fom::Param> read_parameter_csv(const std::string& path, const fom::Problem& problem) {
  // A regular file of at most 256 MiB (millions of queries): never /dev/zero.
  std::string all = read_input_file(path, "parameter file", std::uintmax_t{1} << 28), header;
  // Line ends of every system: CRLF, LF, and a lone CR (old Mac spreadsheets).
  for (size_t i = 0; i < all.size(); ++i)
    if (all[i] == '\r' && (i + 1 == all.size() || all[i + 1] != '\n')) all[i] = '\n';
  // An optional header naming the components becomes a comment (line numbers kept).
  for (const std::string& name : problem.param_names()) header += (header.empty() ? "" : ",") + name;
  size_t start = 0;
  while (start < all.size()) {
    size_t end = all.find('\n', start);
    if (end == std::string::npos) end = all.size();
    std::string line = all.substr(start, end - start);
    std::string compact;
    for (char c : line)
      if (c != ' ' && c != '\t' && c != '\r') compact += c;
    if (compact.empty() || compact[0] == '#') {
      start = end + 1;
      continue;
    }
    if (compact == header) {
      all[start] = '#';
      break;
    }
    // A line of names that are not the parameters in order: a wrong header, not a
    // number that failed to parse.
    bool names = false;
    for (size_t a = 0; a <= compact.size() && !names;) {
      size_t b = compact.find(',', a);
      if (b == std::string::npos) b = compact.size();
      const std::string token = compact.substr(a, b - a);
      char* rest = nullptr;
      (void)std::strtod(token.c_str(), &rest);
      names = !token.empty() && (rest == token.c_str() || *rest != '\0') &&
              (std::isalpha(static_cast<unsigned char>(token[0])) || token[0] == '_');
      a = b + 1;
    }
    if (names) {
      const size_t line_number = static_cast<size_t>(std::count(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(start), '\n')) + 1;
      throw InputError("parameter file " + quoted(path, 200) + " line " + std::to_string(line_number) + ": header " +
                       quoted(compact, 200) + " does not name the parameters of " + quoted(problem.name(), 200) +
                       " in order; expected " + quoted(header, 200) + " or no header");
    }
    break;
  }
  std::istringstream lines(all);
  std::vector<std::size_t> row_lines;
  const Eigen::MatrixXd values = read_dense_csv(lines, "parameter file " + quoted(path, 200), &row_lines);
  if (values.cols() != problem.num_params())
    throw InputError("parameter file " + quoted(path, 200) + " has " + std::to_string(values.cols()) + " values per line, but " +
                     problem.name() + " has " + std::to_string(problem.num_params()) + " parameters (" + header + ")");
  std::vector<fom::Param> out;
  for (Eigen::Index i = 0; i < values.rows(); ++i) {
    const fom::Param mu = values.row(i).transpose();
    try {
      problem.check_param(mu);
    } catch (const InputError& e) {
      throw InputError("parameter file " + quoted(path, 200) + " line " + std::to_string(row_lines[static_cast<size_t>(i)]) +
                       ": " + e.what());
    }
    out.push_back(mu);
  }
  return out;
}

void write_query_csv(const std::string& path, const OnlineModel& rom, const std::vector<OnlineResult>& results,
                     const std::vector<FallbackAnswer>& fallback) {
  write_file_atomically(path, query_csv_writer(rom, results, fallback));
}

namespace {

/// A CSV field: as it is, or quoted (inner quotes doubled) when it holds a comma, a
/// quote or a line break.
std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

}  // namespace

FileWriter query_csv_writer(const OnlineModel& rom, const std::vector<OnlineResult>& results,
                            const std::vector<FallbackAnswer>& fallback) {
  return [&rom, &results, &fallback](std::ostream& out) {
    const bool with_fallback = fallback.size() == results.size() && !fallback.empty();
    for (const std::string& name : rom.problem().param_names()) out << name << ',';
    out << "status,converged,iterations,sparsity,contact_force,time_s,selected,coefficients,penetration,separation,primal_estimate,dual_estimate"
        << (with_fallback ? ",source,fallback_reason,rom_status,rom_primal_estimate,rom_dual_estimate,rom_time_s,fom_time_s\n"
                          : "\n");
    for (size_t i = 0; i < results.size(); ++i) {
      const OnlineResult& res = results[i];
      for (int k = 0; k < res.mu.size(); ++k) out << format_number(res.mu(k)) << ',';
      out << to_string(res.status) << ',' << (res.converged ? 1 : 0) << ',' << res.iterations << ','
          << res.selected.size() << ',' << format_number(res.contact_force) << ','
          << format_number(res.time_s) << ',';
      for (size_t j = 0; j < res.selected.size(); ++j)
        out << (j ? " " : "") << rom.model().dictionary_snapshots()[static_cast<size_t>(res.selected[j])];
      out << ',';
      for (Eigen::Index j = 0; j < res.coefficients.size(); ++j) out << (j ? " " : "") << format_number(res.coefficients(j));
      out << ',' << format_number(res.contact.penetration) << ',' << format_number(res.contact.complementarity)
          << ',' << format_number(res.primal_estimate) << ',' << format_number(res.dual_estimate);
      if (with_fallback) {
        const FallbackAnswer& f = fallback[i];
        out << ',' << (f.from_fom ? "fom" : "rom") << ',' << csv_field(f.reason) << ',' << to_string(f.rom_status) << ','
            << format_number(f.rom_primal_estimate) << ',' << format_number(f.rom_dual_estimate) << ','
            << format_number(f.rom_time_s) << ',' << format_number(f.fom_time_s);
      }
      out << '\n';
    }
  };
}

}  // namespace contactrom::rom
