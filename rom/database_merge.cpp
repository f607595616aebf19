#include <contactrom/rom/database_merge.hpp>

#include <algorithm>
#include <stdexcept>

#include <contactrom/core/format.hpp>

namespace contactrom::rom {
namespace {

/// Throws unless `b` describes the same discrete problem and training options as `a`.
void check_compatible(const SnapshotDatabase& a, const std::string& name_a, const SnapshotDatabase& b,
                      const std::string& name_b) {
  auto differ = [&](const std::string& what, const std::string& va, const std::string& vb) {
    throw InputError("cannot merge " + quoted(name_b, 200) + " into " + quoted(name_a, 200) + ": " + what + " " + vb + " differs from " +
                     va + "; expected databases of the same problem and training set");
  };
  if (a.problem.name != b.problem.name) differ("problem", a.problem.name, b.problem.name);
  if (a.problem.fingerprint != b.problem.fingerprint) differ("mesh fingerprint", a.problem.fingerprint, b.problem.fingerprint);
  if (a.problem.param_names != b.problem.param_names) differ("parameter names", join(a.problem.param_names, ","), join(b.problem.param_names, ","));
  if (a.training_kind != b.training_kind || a.training_size != b.training_size)
    differ("training set", a.training_kind + " " + std::to_string(a.training_size),
           b.training_kind + " " + std::to_string(b.training_size));
  if (a.num_dofs() != b.num_dofs() || a.num_constraints() != b.num_constraints())
    differ("size (dofs x constraints)", std::to_string(a.num_dofs()) + "x" + std::to_string(a.num_constraints()),
           std::to_string(b.num_dofs()) + "x" + std::to_string(b.num_constraints()));
}

/// Index of `mu` in `params` (exact match: both come from the same training set), or −1.
int index_of(const std::vector<fom::Param>& params, const fom::Param& mu) {
  for (size_t i = 0; i < params.size(); ++i)
    if (params[i] == mu) return static_cast<int>(i);
  return -1;
}

/// The snapshots of `db` in the order `order` (a permutation of its columns).
SnapshotDatabase reordered(const SnapshotDatabase& db, const std::vector<int>& order) {
  SnapshotDatabase out = db;
  for (size_t j = 0; j < order.size(); ++j) {
    const int k = order[j];
    out.parameters.col(j) = db.parameters.col(k);
    if (db.primal_in_memory())
      out.primal.col(j) = db.primal.col(k);
    else
      out.primal_refs[j] = db.primal_refs[k];
    out.dual.col(j) = db.dual.col(k);
    out.status[j] = db.status[k];
    out.iterations[j] = db.iterations[k];
    out.pairing_iterations[j] = db.pairing_iterations[k];
    out.time_s[j] = db.time_s[k];
  }
  return out;
}

}  // namespace

std::pair<int, int> part_range(int n, int k, int parts, int chain) {
  if (parts < 1 || k < 1 || k > parts)
    throw InputError("part " + std::to_string(k) + "/" + std::to_string(parts) + " invalid; expected k/K with 1 <= k <= K");
  const long long c = std::max(chain, 1), chains = (n + c - 1) / c;
  const auto end = [&](long long part) { return static_cast<int>(std::min<long long>(n, part * chains / parts * c)); };
  return {end(k - 1), end(k)};
}

SnapshotDatabase merge_databases(const std::vector<SnapshotDatabase>& databases, const std::vector<std::string>& names) {
  if (databases.empty() || names.size() != databases.size())
    throw InputError("merge needs at least one database, and a name for each");
  for (size_t d = 1; d < databases.size(); ++d) check_compatible(databases[0], names[0], databases[d], names[d]);
  int n = 0;
  for (const auto& db : databases) n += db.num_snapshots();

  // Snapshots on disk stay there: the merged database refers to their files.
  const bool on_disk = !databases[0].primal_in_memory();
  for (const auto& db : databases)
    if (db.primal_in_memory() == on_disk)
      throw std::invalid_argument("merge_databases: databases with primal snapshots in memory and on disk");
  SnapshotDatabase out = databases[0];
  out.parameters.resize(databases[0].parameters.rows(), n);
  out.primal.resize(databases[0].num_dofs(), on_disk ? 0 : n);
  out.primal_files.clear();
  out.primal_refs.clear();
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
      if (on_disk)
        out.primal_refs.push_back({db.primal_refs[k].file + static_cast<int>(out.primal_files.size()), db.primal_refs[k].row});
      else
        out.primal.col(j) = db.primal.col(k);
      out.dual.col(j) = db.dual.col(k);
      ++j;
    }
    out.primal_files.insert(out.primal_files.end(), db.primal_files.begin(), db.primal_files.end());
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

void check_appendable(const SnapshotDatabase& db, const std::string& path, const fom::Problem& problem,
                      const std::string& training_kind, int training_size) {
  check_database_problem(db, problem, path);
  if (db.training_kind != training_kind || db.training_size != training_size)
    throw InputError("cannot append to " + quoted(path, 200) + ": its training set " + db.training_kind + " " +
                     std::to_string(db.training_size) + " differs from " + training_kind + " " +
                     std::to_string(training_size) + "; expected the same --train or --level");
  const std::vector<fom::Param> training = fom::training_set(problem, training_size);
  for (int j = 0; j < db.num_snapshots(); ++j)
    if (index_of(training, db.parameter(j)) < 0)
      throw InputError("cannot append to " + quoted(path, 200) + ": its snapshot " + std::to_string(j) +
                       " is not at a parameter of its training set; expected a database written by contactrom offline");
}

std::vector<fom::Param> parameters_not_in(const SnapshotDatabase& db, const std::vector<fom::Param>& params) {
  std::vector<fom::Param> missing;
  for (const fom::Param& mu : params) {
    bool stored = false;
    for (int j = 0; j < db.num_snapshots() && !stored; ++j) stored = db.parameters.col(j) == mu;
    if (!stored) missing.push_back(mu);
  }
  return missing;
}

SnapshotDatabase sorted_by_training(const SnapshotDatabase& db, const std::string& name,
                                    const std::vector<fom::Param>& training) {
  std::vector<std::pair<int, int>> position(db.num_snapshots());
  for (int j = 0; j < db.num_snapshots(); ++j) {
    position[j] = {index_of(training, db.parameter(j)), j};
    if (position[j].first < 0)
      throw InputError("cannot sort the snapshots of " + quoted(name, 200) + ": snapshot " + std::to_string(j) +
                       " is not at a parameter of the training set");
  }
  std::sort(position.begin(), position.end());
  std::vector<int> order;
  for (const auto& p : position) order.push_back(p.second);
  return reordered(db, order);
}

SnapshotDatabase merge_in_training_order(const std::vector<SnapshotDatabase>& databases,
                                         const std::vector<std::string>& names) {
  for (size_t d = 0; d < databases.size(); ++d)
    if (databases[d].training_kind == "adaptive")
      throw InputError("cannot merge " + quoted(names[d], 200) +
                       ": it is an adaptive database, built in rounds from the indicator; expected parts of a grid "
                       "run (offline --part), or continue it with offline --adaptive --append");
  const SnapshotDatabase merged = merge_databases(databases, names);
  const auto problem = rebuild_database_problem(databases[0], names[0]);
  return sorted_by_training(merged, names[0], fom::training_set(*problem, merged.training_size));
}

SnapshotDatabase append_snapshots(const SnapshotDatabase& db, const std::string& name, const SnapshotDatabase& added,
                                  const std::vector<fom::Param>& training) {
  return sorted_by_training(merge_databases({db, added}, {name, "the new snapshots"}), name, training);
}

}  // namespace contactrom::rom
