// Profile combination and Kaiser penalization of multivariate ClaSP (paper II-C); the recursion
// that uses them is in multivariate_segmentation.cpp.
#include "lfd_core/segmentation/multivariate_segmentation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace lfd {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kMinScoreForLog = 1e-12;

}  // namespace

ProfileCombination parseProfileCombination(const std::string& name) {
  if (name == "average") return ProfileCombination::kAverage;
  if (name == "product") return ProfileCombination::kProduct;
  if (name == "weighted_average") return ProfileCombination::kWeightedAverage;
  if (name == "weighted_product") return ProfileCombination::kWeightedProduct;
  if (name == "distance_average") return ProfileCombination::kDistanceAverage;
  if (name == "weighted_distance_average") return ProfileCombination::kWeightedDistanceAverage;
  throw std::invalid_argument("unknown profile combination '" + name +
                              "' (average, product, weighted_average, weighted_product, "
                              "distance_average, weighted_distance_average)");
}

bool isWeighted(ProfileCombination c) {
  return c == ProfileCombination::kWeightedAverage || c == ProfileCombination::kWeightedProduct ||
         c == ProfileCombination::kWeightedDistanceAverage;
}

std::string toString(ProfileCombination combination) {
  switch (combination) {
    case ProfileCombination::kAverage:
      return "average";
    case ProfileCombination::kProduct:
      return "product";
    case ProfileCombination::kWeightedAverage:
      return "weighted_average";
    case ProfileCombination::kWeightedProduct:
      return "weighted_product";
    case ProfileCombination::kDistanceAverage:
      return "distance_average";
    case ProfileCombination::kWeightedDistanceAverage:
      return "weighted_distance_average";
  }
  return "?";
}

Eigen::VectorXd combineProfiles(const std::vector<Eigen::VectorXd>& profiles,
                                const std::vector<double>& weights,
                                ProfileCombination combination) {
  if (profiles.empty()) throw std::invalid_argument("combineProfiles: no profiles");
  const Eigen::Index n = profiles.front().size();
  for (const auto& p : profiles)
    if (p.size() != n) throw std::invalid_argument("combineProfiles: profiles differ in length");
  std::vector<double> w(profiles.size(), 1.0);
  if (isWeighted(combination) && !weights.empty()) {
    if (weights.size() != profiles.size())
      throw std::invalid_argument("combineProfiles: " + std::to_string(weights.size()) +
                                  " weights for " + std::to_string(profiles.size()) + " profiles");
    w = weights;
  }
  double total = 0.0;
  for (double v : w) {
    if (!(v >= 0.0) || !std::isfinite(v))
      throw std::invalid_argument("combineProfiles: weights must be finite and >= 0");
    total += v;
  }
  if (!(total > 0.0)) throw std::invalid_argument("combineProfiles: weights sum to zero");
  const bool product = combination == ProfileCombination::kProduct ||
                       combination == ProfileCombination::kWeightedProduct;

  Eigen::VectorXd out(n);
  for (Eigen::Index t = 0; t < n; ++t) {
    double acc = 0.0;
    bool defined = true;
    for (std::size_t f = 0; f < profiles.size() && defined; ++f) {
      const double p = profiles[f][t];
      if (std::isnan(p)) {
        defined = false;
      } else if (w[f] > 0.0) {
        acc += w[f] * (product ? std::log(std::max(p, kMinScoreForLog)) : p);
      }
    }
    out[t] = !defined ? kNaN : product ? std::exp(acc / total) : acc / total;
  }
  return out;
}

Eigen::VectorXd kaiserWindow(std::size_t n, double beta) {
  if (!(beta >= 0.0) || !std::isfinite(beta))
    throw std::invalid_argument("kaiserWindow: beta must be finite and >= 0");
  Eigen::VectorXd win(static_cast<Eigen::Index>(n));
  if (n == 1) {
    win[0] = 1.0;
    return win;
  }
  // I0, the zeroth-order modified Bessel function of the first kind (C++17 special math).
  const double norm = std::cyl_bessel_i(0.0, beta);
  for (std::size_t k = 0; k < n; ++k) {
    const double r = 2.0 * static_cast<double>(k) / static_cast<double>(n - 1) - 1.0;
    win[static_cast<Eigen::Index>(k)] =
        std::cyl_bessel_i(0.0, beta * std::sqrt(std::max(0.0, 1.0 - r * r))) / norm;
  }
  return win;
}

}  // namespace lfd
