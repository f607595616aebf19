#include <contactrom/fom/delassus.hpp>

#include <algorithm>
#include <utility>

namespace contactrom::fom {
namespace {

/// dst = Σ_k v[k] src[k] (accumulate: dst + Σ_k …) over n entries, the terms added
/// one after the other in k's order for every entry, as a sequence of axpys would,
/// but with one pass over dst instead of one per term.
template <int K>
void combine_columns(double* dst, const double* const* src, const double* v, Eigen::Index n, bool accumulate) {
  for (Eigen::Index i = 0; i < n; ++i) {
    double sum = accumulate ? dst[i] + v[0] * src[0][i] : v[0] * src[0][i];
    for (int k = 1; k < K; ++k) sum += v[k] * src[k][i];
    dst[i] = sum;
  }
}

/// The entries of row `r` of `c`: positions begin … end of its inner index and value arrays.
std::pair<int, int> row_entries(const ConstraintMatrix& c, int r) {
  const int begin = c.outerIndexPtr()[r];
  return {begin, c.isCompressed() ? c.outerIndexPtr()[r + 1] : begin + c.innerNonZeroPtr()[r]};
}

}  // namespace

void delassus_parts(const ConstraintMatrix& c, const std::vector<int>& rows, const Eigen::MatrixXd& s,
                    Eigen::MatrixXd& sct) {
  const Eigen::Index n = s.rows();
  sct.resize(n, static_cast<Eigen::Index>(rows.size()));
  const int* inner = c.innerIndexPtr();
  const double* value = c.valuePtr();
  for (size_t a = 0; a < rows.size(); ++a) {
    double* dst = sct.col(static_cast<Eigen::Index>(a)).data();
    const auto [begin, end] = row_entries(c, rows[a]);
    if (begin == end) {
      std::fill(dst, dst + n, 0.0);
      continue;
    }
    for (int first = begin; first < end; first += 8) {
      const double* src[8];
      const int count = std::min(8, end - first);
      for (int k = 0; k < count; ++k) src[k] = s.col(inner[first + k]).data();
      const bool accumulate = first > begin;
      switch (count) {
        case 1: combine_columns<1>(dst, src, value + first, n, accumulate); break;
        case 2: combine_columns<2>(dst, src, value + first, n, accumulate); break;
        case 3: combine_columns<3>(dst, src, value + first, n, accumulate); break;
        case 4: combine_columns<4>(dst, src, value + first, n, accumulate); break;
        case 5: combine_columns<5>(dst, src, value + first, n, accumulate); break;
        case 6: combine_columns<6>(dst, src, value + first, n, accumulate); break;
        case 7: combine_columns<7>(dst, src, value + first, n, accumulate); break;
        default: combine_columns<8>(dst, src, value + first, n, accumulate); break;
      }
    }
  }
}

/// G_W = C_W S C_Wᵀ from S C_Wᵀ (|W| x |W|): entry (a, b) is row W[a] applied to
/// column b of S C_Wᵀ, its terms added in the row's order. Four columns at a time,
/// every row against them before the next four (they stay in cache): each entry is
/// a chain of dependent additions, and four chains run side by side.
Eigen::MatrixXd delassus(const ConstraintMatrix& c, const std::vector<int>& rows, const Eigen::MatrixXd& sct) {
  const int nw = static_cast<int>(rows.size());
  const Eigen::Index ld = sct.rows();
  const int* inner = c.innerIndexPtr();
  const double* value = c.valuePtr();
  Eigen::MatrixXd g(nw, nw);
  int b = 0;
  for (; b + 4 <= nw; b += 4) {
    const double* col = sct.col(b).data();
    for (int a = 0; a < nw; ++a) {
      double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
      const auto [begin, end] = row_entries(c, rows[a]);
      for (int k = begin; k < end; ++k) {
        const double v = value[k];
        const double* x = col + inner[k];
        s0 += v * x[0];
        s1 += v * x[ld];
        s2 += v * x[2 * ld];
        s3 += v * x[3 * ld];
      }
      g(a, b) = s0, g(a, b + 1) = s1, g(a, b + 2) = s2, g(a, b + 3) = s3;
    }
  }
  for (; b < nw; ++b) {
    const double* col = sct.col(b).data();
    for (int a = 0; a < nw; ++a) {
      double sum = 0.0;
      const auto [begin, end] = row_entries(c, rows[a]);
      for (int k = begin; k < end; ++k) sum += value[k] * col[inner[k]];
      g(a, b) = sum;
    }
  }
  return g;
}

void delassus_lower(const ConstraintMatrix& c, const Eigen::MatrixXd& sct, Eigen::MatrixXd& g) {
  const int m = static_cast<int>(c.rows());
  g.resize(m, m);
  const int* inner = c.innerIndexPtr();
  const double* value = c.valuePtr();
  for (int b = 0; b < m; ++b) {
    const double* col = sct.col(b).data();
    for (int a = b; a < m; ++a) {
      const auto [begin, end] = row_entries(c, a);
      double sum;
      if (end - begin == 6) {  // a 2D node-to-segment row: two chains of three
        const int* i = inner + begin;
        const double* v = value + begin;
        const double s0 = v[0] * col[i[0]] + v[2] * col[i[2]] + v[4] * col[i[4]];
        const double s1 = v[1] * col[i[1]] + v[3] * col[i[3]] + v[5] * col[i[5]];
        sum = s0 + s1;
      } else {
        sum = 0.0;
        for (int k = begin; k < end; ++k) sum += value[k] * col[inner[k]];
      }
      g(a, b) = sum;
    }
  }
}

}  // namespace contactrom::fom
