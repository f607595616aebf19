#include <contactrom/rom/offline_mpi.hpp>

#include <mpi.h>

#include <chrono>
#include <cstdlib>
#include <stdexcept>

namespace contactrom::rom::mpi {
namespace {

/// Values stored per snapshot besides its primal and dual columns: status,
/// iterations, pairing iterations (small integers, exact as doubles) and time.
constexpr int kScalarsPerSnapshot = 4;

/// Sends the failing rank's message to every rank (MPI_Bcast from that rank).
std::string broadcast_message(const std::string& message, int root) {
  int length = static_cast<int>(message.size());
  MPI_Bcast(&length, 1, MPI_INT, root, MPI_COMM_WORLD);
  std::string text(message);
  text.resize(static_cast<size_t>(length));
  MPI_Bcast(text.data(), length, MPI_CHAR, root, MPI_COMM_WORLD);
  return text;
}

/// Local snapshots packed one after the other: primal (unless streamed to a file:
/// nd = 0), dual, then the scalars.
std::vector<double> pack(const SnapshotDatabase& db, int nd) {
  const int nc = db.num_constraints(), stride = nd + nc + kScalarsPerSnapshot;
  std::vector<double> buffer(static_cast<size_t>(stride) * db.num_snapshots());
  for (int k = 0; k < db.num_snapshots(); ++k) {
    double* p = buffer.data() + static_cast<size_t>(stride) * k;
    if (nd > 0) Eigen::Map<Eigen::VectorXd>(p, nd) = db.primal.col(k);
    Eigen::Map<Eigen::VectorXd>(p + nd, nc) = db.dual.col(k);
    p[nd + nc] = static_cast<double>(static_cast<int>(db.status[k]));
    p[nd + nc + 1] = db.iterations[k];
    p[nd + nc + 2] = db.pairing_iterations[k];
    p[nd + nc + 3] = db.time_s[k];
  }
  return buffer;
}

/// Every rank's `path`, on rank 0 (in rank order; empty elsewhere).
std::vector<std::string> gather_paths(const std::string& path, int rank, int size) {
  int length = static_cast<int>(path.size()), longest = 0;
  MPI_Allreduce(&length, &longest, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  std::string mine = path;
  mine.resize(static_cast<size_t>(longest), '\0');
  std::string all(rank == 0 ? static_cast<size_t>(longest) * size : 0, '\0');
  MPI_Gather(mine.data(), longest, MPI_CHAR, all.data(), longest, MPI_CHAR, 0, MPI_COMM_WORLD);
  std::vector<std::string> out;
  for (int r = 0; rank == 0 && r < size; ++r) {
    std::string p = all.substr(static_cast<size_t>(r) * longest, static_cast<size_t>(longest));
    out.push_back(p.substr(0, p.find('\0')));
  }
  return out;
}

/// The parameters of rank `rank` of `size`: the chains c ≡ rank (mod size) of length
/// `chain` (generate_snapshots' continuation), whole, in increasing order.
std::vector<int> rank_share(int n, int chain, int rank, int size) {
  std::vector<int> out;
  for (int c = rank; static_cast<long long>(c) * chain < n; c += size)
    for (int j = c * chain; j < std::min(n, (c + 1) * chain); ++j) out.push_back(j);
  return out;
}

}  // namespace

bool launched_by_mpi() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK"})
    if (std::getenv(name)) return true;
  return false;
}

Session::Session() {
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (!initialised) MPI_Init(nullptr, nullptr);
  MPI_Comm_rank(MPI_COMM_WORLD, &m_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &m_size);
}

Session::~Session() {
  int finalised = 0;
  MPI_Finalized(&finalised);
  if (finalised) return;
  MPI_Barrier(MPI_COMM_WORLD);
  MPI_Finalize();
}

bool active() {
  int initialised = 0, finalised = 0;
  MPI_Initialized(&initialised);
  MPI_Finalized(&finalised);
  return initialised && !finalised;
}

int world_rank() {
  int rank = 0;
  if (active()) MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank;
}

int world_size() {
  int size = 1;
  if (active()) MPI_Comm_size(MPI_COMM_WORLD, &size);
  return size;
}

void max_over_ranks(std::vector<double>& values) {
  MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
}

bool all_ranks_ok(bool ok) {
  int local = ok ? 1 : 0, all = 0;
  MPI_Allreduce(&local, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  return all == 1;
}

namespace {

/// generate_snapshots_distributed(), the database on rank 0 only or (`everywhere`) on every rank.
SnapshotDatabase distributed(const fom::Problem& problem, const std::vector<fom::Param>& params,
                             const std::string& training_kind, int training_size, const OfflineOptions& options,
                             bool everywhere) {
  const auto t0 = std::chrono::steady_clock::now();
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  for (const fom::Param& mu : params) problem.check_param(mu);  // same outcome on every rank
  const int n = static_cast<int>(params.size());

  const int chain = std::max(options.chain, 1);
  std::vector<fom::Param> mine;
  for (int j : rank_share(n, chain, rank, size)) mine.push_back(params[j]);
  OfflineOptions local_options = options;
  if (rank != 0) local_options.progress = nullptr;
  SnapshotDatabase local;
  std::string error;
  try {
    local = generate_snapshots(problem, mine, training_kind, training_size, local_options);
  } catch (const std::exception& e) {
    error = e.what();
  } catch (...) {
    error = "unknown error";
  }
  // Every rank learns whether (and where) a computation failed before any gather,
  // so that no rank waits for data that will never come.
  int failed_rank = error.empty() ? size : rank, first_failed = size;
  MPI_Allreduce(&failed_rank, &first_failed, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (first_failed < size)
    throw RankFailure("rank " + std::to_string(first_failed) + " of " + std::to_string(size) +
                      " failed: " + broadcast_message(error, first_failed));

  // Streamed runs gather everything but the primal snapshots, which stay in each
  // rank's file (the database refers to them; the caller writes it and removes them).
  const bool streamed = !options.stream_to.empty();
  const int nd = streamed ? 0 : problem.num_dofs(), nc = problem.contact().num_constraints();
  const int stride = nd + nc + kScalarsPerSnapshot;
  const std::vector<double> buffer = pack(local, nd);
  const std::vector<std::string> files = streamed ? gather_paths(options.stream_to, rank, size) : std::vector<std::string>{};
  std::vector<std::vector<int>> shares(size);
  for (int r = 0; r < size; ++r) shares[r] = rank_share(n, chain, r, size);
  std::vector<int> counts(size), displs(size);
  for (int r = 0, offset = 0; r < size; ++r) {
    counts[r] = static_cast<int>(shares[r].size()) * stride;
    displs[r] = offset;
    offset += counts[r];
  }
  std::vector<double> all(rank == 0 || everywhere ? static_cast<size_t>(n) * stride : 0);
  int local_threads = local.threads, threads = 0;
  if (everywhere) {
    MPI_Allgatherv(buffer.data(), static_cast<int>(buffer.size()), MPI_DOUBLE, all.data(), counts.data(),
                   displs.data(), MPI_DOUBLE, MPI_COMM_WORLD);
    MPI_Allreduce(&local_threads, &threads, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  } else {
    MPI_Gatherv(buffer.data(), static_cast<int>(buffer.size()), MPI_DOUBLE, all.data(), counts.data(), displs.data(),
                MPI_DOUBLE, 0, MPI_COMM_WORLD);
    MPI_Reduce(&local_threads, &threads, 1, MPI_INT, MPI_SUM, 0, MPI_COMM_WORLD);
    if (rank != 0) return SnapshotDatabase{};
  }

  // Rank r's k-th snapshot is parameter j = shares[r][k].
  SnapshotDatabase db = local;  // metadata (problem, fingerprint, names, ...) of rank 0
  db.parameters.resize(problem.num_params(), n);
  db.primal.resize(problem.num_dofs(), streamed ? 0 : n);
  db.primal_files = files;
  db.primal_refs.assign(streamed ? n : 0, {});
  db.dual.resize(nc, n);
  db.status.assign(n, Status::Success);
  db.iterations.assign(n, 0);
  db.pairing_iterations.assign(n, 0);
  db.time_s.assign(n, 0.0);
  for (int r = 0; r < size; ++r)
    for (int k = 0; k < static_cast<int>(shares[r].size()); ++k) {
      const int j = shares[r][k];
      const double* p = all.data() + displs[r] + static_cast<size_t>(stride) * k;
      db.parameters.col(j) = params[j];
      if (streamed)
        db.primal_refs[j] = {r, k};
      else
        db.primal.col(j) = Eigen::Map<const Eigen::VectorXd>(p, nd);
      db.dual.col(j) = Eigen::Map<const Eigen::VectorXd>(p + nd, nc);
      db.status[j] = static_cast<Status>(static_cast<int>(p[nd + nc]));
      db.iterations[j] = static_cast<int>(p[nd + nc + 1]);
      db.pairing_iterations[j] = static_cast<int>(p[nd + nc + 2]);
      db.time_s[j] = p[nd + nc + 3];
    }
  db.threads = threads;
  db.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return db;
}

}  // namespace

SnapshotDatabase generate_snapshots_distributed(const fom::Problem& problem, const std::vector<fom::Param>& params,
                                                const std::string& training_kind, int training_size,
                                                const OfflineOptions& options) {
  return distributed(problem, params, training_kind, training_size, options, false);
}

SnapshotDatabase generate_snapshots_on_every_rank(const fom::Problem& problem, const std::vector<fom::Param>& params,
                                                  const std::string& training_kind, int training_size,
                                                  const OfflineOptions& options) {
  if (!options.stream_to.empty())
    throw std::invalid_argument("generate_snapshots_on_every_rank: the snapshots cannot be streamed to a file");
  return distributed(problem, params, training_kind, training_size, options, true);
}

}  // namespace contactrom::rom::mpi
