#include "rom/database_merge.hpp"

#include <algorithm>

namespace contactrom::rom {
namespace {

/// Throws unless `b` describes the same discrete problem and training options as `a`.
void check_compatible(const SnapshotDatabase& a, const std::string& name_a, const SnapshotDatabase& b,
                      const std::string& name_b) {
  auto differ = [&](const std::string& what, const std::string& va, const std::string& vb) {
    throw InputError("cannot merge '" + name_b + "' into '" + name_a + "': " + what + " " + vb + " differs from " +
                     va + "; expected databases of the same problem and training set");
  };
  if (a.problem != b.problem) differ("problem", a.problem, b.problem);
  if (a.mesh_fingerprint != b.mesh_fingerprint) differ("mesh fingerprint", a.mesh_fingerprint, b.mesh_fingerprint);
  auto join = [](const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : ",") + x;
    return s;
  };
  if (a.param_names != b.param_names) differ("parameter names", join(a.param_names), join(b.param_names));
  if (a.training_kind != b.training_kind || a.training_size != b.training_size)
    differ("training set", a.training_kind + " " + std::to_string(a.training_size),
           b.training_kind + " " + std::to_string(b.training_size));
  if (a.num_dofs() != b.num_dofs() || a.num_constraints() != b.num_constraints())
    differ("size (dofs x constraints)", std::to_string(a.num_dofs()) + "x" + std::to_string(a.num_constraints()),
           std::to_string(b.num_dofs()) + "x" + std::to_string(b.num_constraints()));
}

}  // namespace

std::pair<int, int> part_range(int n, int k, int parts) {
  if (parts < 1 || k < 1 || k > parts)
    throw InputError("part " + std::to_string(k) + "/" + std::to_string(parts) + " invalid; expected k/K with 1 <= k <= K");
  const long long nn = n;
  return {static_cast<int>((k - 1) * nn / parts), static_cast<int>(k * nn / parts)};
}

SnapshotDatabase merge_databases(const std::vector<SnapshotDatabase>& databases, const std::vector<std::string>& names) {
  if (databases.empty() || names.size() != databases.size())
    throw InputError("merge needs at least one database, and a name for each");
  for (size_t d = 1; d < databases.size(); ++d) check_compatible(databases[0], names[0], databases[d], names[d]);
  int n = 0;
  for (const auto& db : databases) n += db.num_snapshots();

  SnapshotDatabase out = databases[0];
  out.parameters.resize(databases[0].parameters.rows(), n);
  out.primal.resize(databases[0].num_dofs(), n);
  out.dual.resize(databases[0].num_constraints(), n);
  out.status.clear();
  out.iterations.clear();
  out.pairing_iterations.clear();
  out.time_s.clear();
  out.setup_time_s = out.wall_time_s = 0.0;
  out.threads = 0;
  int j = 0;
  for (size_t d = 0; d < databases.size(); ++d) {
    const SnapshotDatabase& db = databases[d];
    for (int k = 0; k < db.num_snapshots(); ++k) {
      for (int i = 0; i < j; ++i)
        if (out.parameters.col(i) == db.parameters.col(k))
          throw InputError("cannot merge '" + names[d] + "': its snapshot " + std::to_string(k) +
                           " has the parameter of an earlier snapshot; expected disjoint parts");
      out.parameters.col(j) = db.parameters.col(k);
      out.primal.col(j) = db.primal.col(k);
      out.dual.col(j) = db.dual.col(k);
      ++j;
    }
    out.status.insert(out.status.end(), db.status.begin(), db.status.end());
    out.iterations.insert(out.iterations.end(), db.iterations.begin(), db.iterations.end());
    out.pairing_iterations.insert(out.pairing_iterations.end(), db.pairing_iterations.begin(),
                                  db.pairing_iterations.end());
    out.time_s.insert(out.time_s.end(), db.time_s.begin(), db.time_s.end());
    out.setup_time_s += db.setup_time_s;
    out.wall_time_s += db.wall_time_s;
    out.threads = std::max(out.threads, db.threads);
  }
  return out;
}

}  // namespace contactrom::rom
