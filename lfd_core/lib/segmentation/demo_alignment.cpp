#include "lfd_core/segmentation/demo_alignment.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "lfd_core/segmentation/time_alignment.hpp"
#include "lfd_core/util/parallel_for.hpp"

namespace lfd {

namespace {

void checkPair(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  if (a.rows() == 0 || b.rows() == 0 || a.cols() != b.cols())
    throw std::invalid_argument("multivariate DTW needs two non-empty series of as many features");
}

}  // namespace

Eigen::MatrixXd onUniformGrid(const Eigen::MatrixXd& features, const std::vector<double>& time,
                              double step) {
  if (time.size() != static_cast<std::size_t>(features.rows()) || time.empty() || !(step > 0))
    throw std::invalid_argument("onUniformGrid: a timestamp per row and a positive step needed");
  const double span = time.back() - time.front();
  const Eigen::Index rows = static_cast<Eigen::Index>(std::floor(span / step)) + 1;
  Eigen::MatrixXd out(rows, features.cols());
  std::size_t j = 0;
  for (Eigen::Index k = 0; k < rows; ++k) {
    const double t = time.front() + static_cast<double>(k) * step;
    while (j + 1 < time.size() && time[j + 1] < t) ++j;
    if (j + 1 >= time.size()) {
      out.row(k) = features.row(static_cast<Eigen::Index>(j));
      continue;
    }
    const double dt = time[j + 1] - time[j];
    const double w = dt > 0 ? std::clamp((t - time[j]) / dt, 0.0, 1.0) : 0.0;
    out.row(k) = (1.0 - w) * features.row(static_cast<Eigen::Index>(j)) +
                 w * features.row(static_cast<Eigen::Index>(j + 1));
  }
  return out;
}

double multivariateDtwCost(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double band) {
  checkPair(a, b);
  return dtwRows(a, b, nullptr, band);
}

std::vector<double> multivariateDtwMap(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b,
                                       double band) {
  checkPair(a, b);
  std::vector<std::pair<int, int>> path;
  dtwRows(a, b, &path, band);
  std::vector<double> sum(static_cast<std::size_t>(a.rows()), 0.0);
  std::vector<double> count(static_cast<std::size_t>(a.rows()), 0.0);
  for (const auto& [i, j] : path) {
    sum[static_cast<std::size_t>(i)] += static_cast<double>(j);
    count[static_cast<std::size_t>(i)] += 1.0;
  }
  for (std::size_t k = 0; k < sum.size(); ++k) sum[k] /= count[k];
  return sum;
}

std::vector<double> anchoredDtwMap(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b,
                                   const std::vector<std::size_t>& a_anchors,
                                   const std::vector<std::size_t>& b_anchors, double band) {
  checkPair(a, b);
  if (a_anchors.size() != b_anchors.size())
    throw std::invalid_argument("anchored DTW needs as many anchors in both series");
  std::vector<std::size_t> a_cuts{0}, b_cuts{0};
  for (std::size_t k = 0; k < a_anchors.size(); ++k) {
    // An anchor must leave both sides a row: others are skipped, not trusted.
    if (a_anchors[k] <= a_cuts.back() || b_anchors[k] <= b_cuts.back() ||
        a_anchors[k] >= static_cast<std::size_t>(a.rows()) ||
        b_anchors[k] >= static_cast<std::size_t>(b.rows()))
      continue;
    a_cuts.push_back(a_anchors[k]);
    b_cuts.push_back(b_anchors[k]);
  }
  a_cuts.push_back(static_cast<std::size_t>(a.rows()));
  b_cuts.push_back(static_cast<std::size_t>(b.rows()));
  std::vector<double> map;
  for (std::size_t k = 0; k + 1 < a_cuts.size(); ++k) {
    const auto rows_a = static_cast<Eigen::Index>(a_cuts[k + 1] - a_cuts[k]);
    const auto rows_b = static_cast<Eigen::Index>(b_cuts[k + 1] - b_cuts[k]);
    const std::vector<double> part =
        multivariateDtwMap(a.middleRows(static_cast<Eigen::Index>(a_cuts[k]), rows_a),
                           b.middleRows(static_cast<Eigen::Index>(b_cuts[k]), rows_b), band);
    for (double row : part) map.push_back(row + static_cast<double>(b_cuts[k]));
  }
  return map;
}

double mapRow(const std::vector<double>& map, double row) {
  if (map.empty()) return 0.0;
  if (row <= 0) return map.front();
  const double last = static_cast<double>(map.size() - 1);
  if (row >= last) return map.back();
  const std::size_t k = static_cast<std::size_t>(row);
  const double w = row - static_cast<double>(k);
  return (1.0 - w) * map[k] + w * map[k + 1];
}

std::vector<std::size_t> byDtwCostToOthers(const std::vector<Eigen::MatrixXd>& gridded, int threads,
                                           double band) {
  const std::size_t n = gridded.size();
  if (n == 0) throw std::invalid_argument("no demonstrations to align");
  for (const Eigen::MatrixXd& g : gridded) checkPair(g, gridded.front());
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = a + 1; b < n; ++b) pairs.emplace_back(a, b);
  std::vector<double> cost(pairs.size());
  parallelFor(pairs.size(), threads, [&](std::size_t p) {
    const auto [a, b] = pairs[p];
    cost[p] = multivariateDtwCost(gridded[a], gridded[b], band) /
              static_cast<double>(gridded[a].rows() + gridded[b].rows());
  });
  std::vector<double> total(n, 0.0);
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    total[pairs[p].first] += cost[p];
    total[pairs[p].second] += cost[p];
  }
  std::vector<std::size_t> order(n);
  for (std::size_t d = 0; d < n; ++d) order[d] = d;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return total[a] < total[b]; });
  return order;
}

std::pair<Eigen::MatrixXd, Eigen::MatrixXd> sharedColumns(
    const std::vector<Eigen::MatrixXd>& gridded, const ColumnMasks& masks, std::size_t a,
    std::size_t b) {
  if (masks.empty()) return {gridded[a], gridded[b]};
  for (std::size_t d : {a, b})
    if (masks[d].size() != static_cast<std::size_t>(gridded[d].cols()))
      throw std::invalid_argument("alignment: a column mask per column of the demo's grid needed");
  std::vector<Eigen::Index> shared;
  for (std::size_t c = 0; c < masks[a].size(); ++c)
    if (masks[a][c] && masks[b][c]) shared.push_back(static_cast<Eigen::Index>(c));
  return {gridded[a](Eigen::all, shared), gridded[b](Eigen::all, shared)};
}

DemoAlignment alignTo(const std::vector<Eigen::MatrixXd>& gridded, std::size_t reference,
                      int threads, double band, const ColumnMasks& masks) {
  const std::size_t n = gridded.size();
  if (reference >= n)
    throw std::invalid_argument("alignTo: no demonstration " + std::to_string(reference) +
                                " to align to");
  for (const Eigen::MatrixXd& g : gridded) checkPair(g, gridded.front());
  DemoAlignment out;
  out.reference = reference;
  out.to_reference.resize(n);
  out.from_reference.resize(n);
  out.mean_cost.assign(n, 0.0);
  if (!masks.empty() && masks.size() != n)
    throw std::invalid_argument("alignTo: one column mask per demo needed");
  parallelFor(n, threads, [&](std::size_t d) {
    const auto [demo, ref] = sharedColumns(gridded, masks, d, reference);
    out.to_reference[d] = multivariateDtwMap(demo, ref, band);
    out.from_reference[d] = multivariateDtwMap(ref, demo, band);
    out.mean_cost[d] = d == reference ? 0.0
                                      : multivariateDtwCost(demo, ref, band) /
                                            static_cast<double>(demo.rows() + ref.rows());
  });
  return out;
}

DemoAlignment alignToMedoid(const std::vector<Eigen::MatrixXd>& gridded, int threads, double band) {
  return alignTo(gridded, byDtwCostToOthers(gridded, threads, band).front(), threads, band);
}

}  // namespace lfd
