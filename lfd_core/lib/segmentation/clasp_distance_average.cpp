// Multivariate k-NN by distance averaging (the ClaSP authors' multivariate anchor, as in claspy):
// for every query subsequence i, each channel's distance profile d_c(i, .) is computed, its
// trivial matches are set to the profile's maximum, the profile is z-normalized (mean 0, std 1)
// so that channels of any scale weigh alike, the channels are averaged (optionally weighted), and
// the k nearest neighbours are taken on that average. One window for every channel.
//
// Cost O(d m^2): per channel the dot products of query i with every j are updated from those of
// query i - 1 along the diagonals (QT_i[j] = QT_{i-1}[j-1] - x[i-1] x[j-1] + x[i+w-1] x[j+w-1]).
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "lfd_core/segmentation/clasp.hpp"

namespace lfd {
namespace {

struct Channel {
  Eigen::VectorXd x;
  Eigen::VectorXd mean, stdev, sumsq;  // per subsequence
  Eigen::VectorXd first_row;           // QT_0[j]
  Eigen::VectorXd qt;                  // QT_i[j] for the current query
};

Channel prepare(const Eigen::Ref<const Eigen::VectorXd>& x, std::size_t w) {
  const Eigen::Index n = x.size(), m = n - static_cast<Eigen::Index>(w) + 1;
  const Eigen::Index iw = static_cast<Eigen::Index>(w);
  Channel c;
  c.x = x;
  c.mean.resize(m);
  c.stdev.resize(m);
  c.sumsq.resize(m);
  c.first_row.resize(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const auto s = x.segment(i, iw);
    c.mean[i] = s.mean();
    c.sumsq[i] = s.squaredNorm();
    c.stdev[i] = std::sqrt(std::max(0.0, c.sumsq[i] / w - c.mean[i] * c.mean[i]));
    c.first_row[i] = x.segment(0, iw).dot(s);
  }
  c.qt = c.first_row;
  return c;
}

}  // namespace

KnnResult distanceAverageKnn(const Eigen::MatrixXd& series, const std::vector<double>& weights,
                             std::size_t window, std::size_t k, std::size_t exclusion_zone,
                             ClaspDistance distance) {
  const std::size_t n = static_cast<std::size_t>(series.rows());
  const std::size_t d = static_cast<std::size_t>(series.cols());
  if (d == 0) throw std::invalid_argument("distance averaging: no channel");
  if (!weights.empty() && weights.size() != d)
    throw std::invalid_argument("distance averaging: one weight per channel needed");
  if (window < 2 || n < 3 * window || k == 0)
    throw std::invalid_argument("distance averaging: series of " + std::to_string(n) +
                                " samples too short for window " + std::to_string(window));
  const std::size_t m = n - window + 1;
  std::vector<Channel> channels;
  for (std::size_t c = 0; c < d; ++c) channels.push_back(prepare(series.col(c), window));
  const double w = static_cast<double>(window);

  KnnResult out;
  out.window = window;
  out.k = k;
  out.num_subsequences = m;
  out.indices.assign(m * k, -1);
  out.distances.assign(m * k, std::numeric_limits<double>::infinity());
  Eigen::VectorXd profile(m), average(m);
  std::vector<std::pair<double, std::int32_t>> order;
  for (std::size_t i = 0; i < m; ++i) {
    average.setZero();
    double weight_sum = 0.0;
    for (std::size_t c = 0; c < d; ++c) {
      Channel& ch = channels[c];
      if (i > 0) {  // slide the dot products of query i - 1 to query i (backwards, in place)
        for (std::size_t j = m - 1; j >= 1; --j)
          ch.qt[j] = ch.qt[j - 1] - ch.x[i - 1] * ch.x[j - 1] +
                     ch.x[i + window - 1] * ch.x[j + window - 1];
        ch.qt[0] = ch.first_row[i];
      }
      const double mi = ch.mean[i], si = ch.stdev[i];
      for (std::size_t j = 0; j < m; ++j) {
        double d2;
        if (distance == ClaspDistance::kEuclidean) {
          d2 = ch.sumsq[i] + ch.sumsq[j] - 2.0 * ch.qt[j];
        } else if (si > 1e-12 && ch.stdev[j] > 1e-12) {
          d2 = 2.0 * w * (1.0 - (ch.qt[j] - w * mi * ch.mean[j]) / (w * si * ch.stdev[j]));
        } else {
          d2 = (si > 1e-12) == (ch.stdev[j] > 1e-12) ? 0.0 : w;  // flat vs shaped: apart
        }
        profile[j] = std::sqrt(std::max(0.0, d2));
      }
      const std::size_t lo = i > exclusion_zone ? i - exclusion_zone : 0;
      const std::size_t hi = std::min(m - 1, i + exclusion_zone);
      const double top = profile.maxCoeff();
      for (std::size_t j = lo; j <= hi; ++j) profile[j] = top;
      const double mean = profile.mean();
      const double sd = std::sqrt((profile.array() - mean).square().mean());
      if (!(sd > 1e-12)) continue;  // a channel flat over this query says nothing
      const double wc = weights.empty() ? 1.0 : weights[c];
      average += wc * (profile.array() - mean).matrix() / sd;
      weight_sum += wc;
    }
    if (weight_sum > 0) average /= weight_sum;
    order.clear();
    for (std::size_t j = 0; j < m; ++j) {
      if (j + exclusion_zone >= i && j <= i + exclusion_zone) continue;  // trivial match
      order.emplace_back(average[j], static_cast<std::int32_t>(j));
    }
    const std::size_t kk = std::min(k, order.size());
    std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(kk), order.end());
    for (std::size_t r = 0; r < kk; ++r) {
      out.indices[i * k + r] = order[r].second;
      out.distances[i * k + r] = order[r].first;
    }
  }
  return out;
}

}  // namespace lfd
