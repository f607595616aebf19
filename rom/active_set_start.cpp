#include <contactrom/rom/active_set_start.hpp>

#include <algorithm>

namespace contactrom::rom {

std::vector<std::pair<std::string, WarmStart>> warm_start_words(const std::vector<WarmStart>& allowed) {
  static const std::vector<std::pair<std::string, WarmStart>> words = {
      {"empty", WarmStart::Empty}, {"cell", WarmStart::Cell}, {"nearest", WarmStart::Nearest}, {"primal", WarmStart::Primal}};
  std::vector<std::pair<std::string, WarmStart>> out;
  for (const WarmStart w : allowed)
    out.push_back(*std::find_if(words.begin(), words.end(), [w](const auto& p) { return p.second == w; }));
  return out;
}

bool ActiveSetStart::begin(const ReducedModel& model, const fom::Param& mu, WarmStart init, OnlineResult& res) {
  if (!k_inv.ok()) {
    res.status = Status::NumericalIssue;
    res.message = "Cholesky factorisation of the reduced stiffness failed";
    res.u_hat = Eigen::VectorXd::Zero(model.primal_rank());
    res.lambda = Eigen::VectorXd::Zero(model.dictionary().rows());
    return false;
  }
  off_s = model.surface_offset(mu);
  k_inv.apply(model.reduced_rhs(mu), u_free);

  start_columns.clear();
  nearest = -1;
  if (init == WarmStart::Empty || model.dictionary_size() == 0) {
    u_start = u_free;
    return true;
  }
  std::vector<ReducedModel::StencilPoint> stencil = model.interpolation_stencil(mu);
  nearest = ReducedModel::nearest_column(stencil);
  if (init == WarmStart::Nearest) stencil = {{nearest, 1.0}};
  // (A quadratic stencil for û, tried on hertz 30, needed more pairing updates on
  // average: the solutions are not smooth in μ where nodes enter contact.)
  if (init != WarmStart::Primal)
    for (const auto& s : stencil)
      for (int c : model.sibling_columns(s.column)) start_columns.push_back(c);
  const Eigen::MatrixXd& coords = model.snapshot_coordinates();
  u_start.setZero(model.primal_rank());
  for (const auto& s : stencil) u_start.noalias() += s.weight * coords.col(s.column);
  return true;
}

void ActiveSetStart::seed(const ReducedModel& model, SupportOperators& ops) const {
  if (nearest >= 0) ops.seed(model.snapshot_search_memory(nearest));
}

}  // namespace contactrom::rom
