#include <contactrom/rom/adaptive_training.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>

#include <contactrom/core/format.hpp>
#include <contactrom/fom/sampling.hpp>
#include <contactrom/rom/database_merge.hpp>
#include <contactrom/rom/error_indicator.hpp>
#include <contactrom/rom/online_methods.hpp>

namespace contactrom::rom {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
/// Largest candidate set (each round answers every candidate).
constexpr int kMaxCandidates = 100000;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Whether `db` holds a snapshot at exactly μ.
bool holds(const SnapshotDatabase& db, const fom::Param& mu) {
  for (int j = 0; j < db.num_snapshots(); ++j)
    if (db.parameters.col(j) == mu) return true;
  return false;
}

/// Appends `round` to the database's record.
void record_round(AdaptiveRecord& record, const AdaptiveRound& round) {
  record.round_snapshots.push_back(round.snapshots);
  record.round_added.push_back(static_cast<int>(round.added.size()));
  record.round_max_indicator.push_back(round.max_indicator);
  record.round_mean_indicator.push_back(round.mean_indicator);
  record.round_time_s.push_back(round.time_s);
}

void check_same(const std::string& path, const std::string& what, const std::string& stored, const std::string& given) {
  if (stored != given)
    throw InputError("cannot continue the adaptive database " + quoted(path, 200) + ": it was built with " + what + " " +
                     stored + ", not " + given + "; expected the same (or leave the option out)");
}

}  // namespace

const OptionTable<AdaptiveOptions>& adaptive_option_table() {
  static const OptionTable<AdaptiveOptions> table = [] {
    OptionTable<AdaptiveOptions> t;
    t.number("tolerance", &AdaptiveOptions::tolerance,
             "ε: stop when the largest indicator over the candidates is below it (a relative error)",
             Interval::greater_than(0))
        .integer("max_snapshots", &AdaptiveOptions::max_snapshots,
                 "N: stop at N snapshots, the initial ones included (the last batch is cut to fit)", 1, 10000000)
        .integer("candidates", &AdaptiveOptions::candidates,
                 "M: candidate parameters, a Latin hypercube of the parameter box", 1, kMaxCandidates)
        .integer("batch", &AdaptiveOptions::batch, "B: FOM snapshots added per round, at most", 1, 100000)
        .integer("seed", &AdaptiveOptions::seed, "seed of the candidates' Latin hypercube", 0, 2147483647)
        .choice("indicator", &AdaptiveOptions::indicator,
                "estimate that ranks the candidates: primal (relative H1), dual (relative L2 on the contact "
                "surface) or max (the larger of the two)",
                {{"primal", "primal"}, {"dual", "dual"}, {"max", "max"}})
        .text("method", &AdaptiveOptions::method, "online method whose answers are estimated",
              [](const std::string& name, const std::string&) { check_online_method(name); })
        .number("delta", [](auto& o) -> auto& { return o.model.delta; }, "POD tolerance of the reduced models",
                Interval::closed(0, 1))
        .integer("initial", &AdaptiveOptions::initial,
                 "size or level of the initial training set (0: the coarsest: level 1, 2 uniform points or the "
                 "listed points)",
                 0, 10000000);
    return t;
  }();
  return table;
}

const OptionTable<AdaptiveOptions>& adaptive_record_table() {
  static const OptionTable<AdaptiveOptions> table = adaptive_option_table().without({"initial"});
  return table;
}

void check_adaptive_options(const AdaptiveOptions& o) {
  adaptive_option_table().check(o, "adaptive training: ");
  if (o.share_count < 1 || o.share_index < 0 || o.share_index >= o.share_count)
    throw InputError("adaptive training: share = " + std::to_string(o.share_index) + " of " +
                     std::to_string(o.share_count) + " invalid; expected an index in [0, count) of a count >= 1");
}

AdaptiveOptions adaptive_options_of(const SnapshotDatabase& db) {
  AdaptiveOptions o;
  for (const auto& [key, value] : db.adaptive.settings)
    adaptive_record_table().assign(o, key, value, "adaptive database setting " + key);
  o.initial = db.training_size;
  return o;
}

AdaptiveTrainer::AdaptiveTrainer(const fom::Problem& problem, AdaptiveOptions options)
    : m_problem(problem), m_options(std::move(options)) {
  check_adaptive_options(m_options);
  if (const std::string why = no_error_estimate_reason(problem); !why.empty())
    throw InputError("adaptive training ranks its candidates by the error estimate of the reduced answers, which "
                     "there is none of: " + why + "; expected a problem whose elastic moduli do not depend on the "
                     "parameters, or a grid (--train, --level)");
  if (!m_options.generate) m_options.generate = [](const fom::Problem& p, const std::vector<fom::Param>& params,
                                                   const std::string& kind, int n, const OfflineOptions& o) {
    return generate_snapshots(p, params, kind, n, o);
  };
  m_options.online.estimate = true;
  m_options.offline.stream_to.clear();  // the batches are merged in memory
  m_options.offline.chain = 1;  // a batch's points are far apart: each is solved from scratch
  m_options.model.keep_primal_snapshots = online_method_needs_primal_snapshots(m_options.method);
  fom::SamplingPlan plan;
  plan.kind = fom::SamplingPlan::Kind::Random;
  plan.seed = static_cast<unsigned>(m_options.seed);
  m_candidates = plan.points_for(problem.parameters(), m_options.candidates);
}

int AdaptiveTrainer::initial_size() const {
  if (m_options.initial > 0) return m_options.initial;
  const fom::SamplingPlan& plan = m_problem.definition().training;
  if (plan.selector() == "list") return static_cast<int>(plan.points.size());
  return plan.selector() == "level" ? 1 : 2;
}

std::vector<fom::Param> AdaptiveTrainer::initial_set() const { return fom::training_set(m_problem, initial_size()); }

double AdaptiveTrainer::indicator(const OnlineResult& answer) const {
  const double p = answer.primal_estimate, d = answer.dual_estimate;
  const double v = m_options.indicator == "primal" ? p : m_options.indicator == "dual" ? d : std::max(p, d);
  return std::isfinite(v) && std::isfinite(p) && std::isfinite(d) ? v : kInfinity;
}

std::vector<double> AdaptiveTrainer::evaluate(const SnapshotDatabase& db, const std::vector<fom::Param>& params) const {
  const ReducedModel model(m_problem, db, m_options.model);
  const std::unique_ptr<OnlineSolver> solver = make_online_solver(m_options.method, model, m_options.online);
  // This process's share (every candidate without MPI), then the other shares' values.
  const int count = m_options.share_count, first = m_options.share_index;
  const int n = static_cast<int>(params.size()), mine = first < n ? (n - first + count - 1) / count : 0;
  std::vector<double> out(params.size(), -kInfinity);
  parallel_for(mine, m_options.offline.threads,
               [&](int k) {
                 const size_t q = static_cast<size_t>(first) + static_cast<size_t>(k) * static_cast<size_t>(count);
                 out[q] = indicator(solver->solve(params[q]));
               },
               m_options.offline.progress);
  if (count > 1 && m_options.gather_indicators) m_options.gather_indicators(out);
  return out;
}

SnapshotDatabase AdaptiveTrainer::run() const {
  const int n = initial_size();
  const std::vector<fom::Param> initial = fom::training_set(m_problem, n);
  if (static_cast<int>(initial.size()) > m_options.max_snapshots)
    throw InputError("max_snapshots = " + std::to_string(m_options.max_snapshots) + " is below the " +
                     std::to_string(initial.size()) + " snapshots of the initial training set; expected at least " +
                     std::to_string(initial.size()));
  SnapshotDatabase db = m_options.generate(m_problem, initial, "adaptive", n, m_options.offline);
  db.training_kind = "adaptive";
  db.adaptive = AdaptiveRecord{};
  db.adaptive.initial_snapshots = static_cast<int>(initial.size());
  return loop(std::move(db));
}

SnapshotDatabase AdaptiveTrainer::resume(SnapshotDatabase db, const std::string& path) const {
  check_database(db, m_problem, path);
  if (db.training_kind != "adaptive")
    throw InputError("cannot continue " + quoted(path, 200) + " adaptively: it holds the training set " +
                     db.training_kind + " " + std::to_string(db.training_size) +
                     "; expected a database written by offline --adaptive");
  const AdaptiveRecord& a = db.adaptive;
  // The settings that define the sequence of rounds (ε, N and B may change).
  const std::map<std::string, OptionValue> ours = adaptive_record_table().to_values(m_options);
  for (const char* key : {"candidates", "seed", "indicator", "method", "delta"}) {
    const auto stored = a.settings.find(key);
    check_same(path, key, stored == a.settings.end() ? "none" : option_text(stored->second), option_text(ours.at(key)));
  }
  check_same(path, "initial training set", std::to_string(db.training_size), std::to_string(initial_size()));
  // A round that added nothing ended the earlier run; it is evaluated again (same
  // indicators) under the new tolerance and N.
  if (a.num_rounds() > 0 && a.round_added.back() == 0) {
    AdaptiveRecord& r = db.adaptive;
    r.round_snapshots.pop_back();
    r.round_added.pop_back();
    r.round_max_indicator.pop_back();
    r.round_mean_indicator.pop_back();
    r.round_time_s.pop_back();
  }
  return loop(std::move(db));
}

SnapshotDatabase AdaptiveTrainer::loop(SnapshotDatabase db) const {
  record_settings(db.adaptive);
  for (;;) {
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<double> indicators;
    AdaptiveRound round = evaluate_round(db, indicators);
    const int room = m_options.max_snapshots - db.num_snapshots();
    for (int i : select_batch(indicators, db, room)) round.added.push_back(m_candidates[static_cast<size_t>(i)]);
    if (round.max_indicator < m_options.tolerance) round.stop = "tolerance";
    else if (room <= 0) round.stop = "max_snapshots";
    else if (round.added.empty()) round.stop = "candidates";
    add_batch(db, round.added);
    round.time_s = seconds_since(t0);
    db.wall_time_s += round.time_s;
    record_round(db.adaptive, round);
    if (m_options.on_round) m_options.on_round(round, db);
    // A run stopped by N evaluates its last model too (a round that adds nothing).
    if (round.added.empty()) return db;
  }
}

void AdaptiveTrainer::record_settings(AdaptiveRecord& record) const {
  record.settings = adaptive_record_table().to_values(m_options);
}

AdaptiveRound AdaptiveTrainer::evaluate_round(const SnapshotDatabase& db, std::vector<double>& indicators) const {
  AdaptiveRound round;
  round.round = db.adaptive.num_rounds();
  round.snapshots = db.num_snapshots();
  std::vector<fom::Param> remaining;
  std::vector<int> index;
  for (size_t i = 0; i < m_candidates.size(); ++i)
    if (!holds(db, m_candidates[i])) remaining.push_back(m_candidates[i]), index.push_back(static_cast<int>(i));
  const std::vector<double> values = evaluate(db, remaining);
  indicators.assign(m_candidates.size(), -kInfinity);
  double sum = 0.0;
  int worst = -1;
  for (size_t q = 0; q < values.size(); ++q) {
    indicators[static_cast<size_t>(index[q])] = values[q];
    if (std::isfinite(values[q])) sum += values[q];
    else ++round.failed;
    if (worst < 0 || values[q] > values[static_cast<size_t>(worst)]) worst = static_cast<int>(q);
  }
  round.candidates = static_cast<int>(remaining.size());
  const int finite = round.candidates - round.failed;
  round.mean_indicator = finite > 0 ? sum / finite : 0.0;
  round.max_indicator = worst < 0 ? 0.0 : values[static_cast<size_t>(worst)];
  if (worst >= 0) round.worst = remaining[static_cast<size_t>(worst)];
  return round;
}

std::vector<int> AdaptiveTrainer::select_batch(const std::vector<double>& indicators, const SnapshotDatabase& db,
                                               int room) const {
  std::vector<int> order;
  for (size_t i = 0; i < indicators.size(); ++i)
    if (indicators[i] >= m_options.tolerance) order.push_back(static_cast<int>(i));
  // Worst first; equal indicators in candidate order.
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return indicators[a] > indicators[b]; });
  const fom::ParameterSpace& space = m_problem.parameters();
  const Eigen::VectorXd scale = (space.upper - space.lower).cwiseInverse();
  const auto unit = [&](const fom::Param& mu) -> Eigen::VectorXd { return (mu - space.lower).cwiseProduct(scale); };
  std::vector<Eigen::VectorXd> trained;
  for (int j = 0; j < db.num_snapshots(); ++j) trained.push_back(unit(db.parameter(j)));
  // A pick at μ is expected to correct the candidates closer to it than the nearest
  // snapshot was: they are left for the next round.
  std::vector<std::pair<Eigen::VectorXd, double>> picked;  // (point, radius²)
  const auto covered = [&](const Eigen::VectorXd& x) {
    for (const auto& [p, r2] : picked)
      if ((x - p).squaredNorm() < r2) return true;
    return false;
  };
  const size_t size = static_cast<size_t>(std::max(0, std::min(m_options.batch, room)));
  std::vector<int> batch;
  std::vector<char> taken(indicators.size(), 0);
  for (int pass = 0; pass < 2; ++pass)
    for (int i : order) {
      if (batch.size() == size) return batch;
      const Eigen::VectorXd x = unit(m_candidates[static_cast<size_t>(i)]);
      if (taken[static_cast<size_t>(i)] || (pass == 0 && covered(x))) continue;
      double r2 = std::numeric_limits<double>::infinity();
      for (const Eigen::VectorXd& t : trained) r2 = std::min(r2, (x - t).squaredNorm());
      taken[static_cast<size_t>(i)] = 1;
      picked.push_back({x, r2});
      batch.push_back(i);
    }
  return batch;
}

void AdaptiveTrainer::add_batch(SnapshotDatabase& db, const std::vector<fom::Param>& batch) const {
  if (batch.empty()) return;
  SnapshotDatabase added = m_options.generate(m_problem, batch, "adaptive", db.training_size, m_options.offline);
  added.training_kind = "adaptive";
  const AdaptiveRecord record = db.adaptive;
  const double wall = db.wall_time_s;
  db = merge_databases({db, added}, {"the adaptive database", "the new snapshots"});
  db.adaptive = record;
  db.wall_time_s = wall;  // the round's time is added by the loop
}

}  // namespace contactrom::rom
