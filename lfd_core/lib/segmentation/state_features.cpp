// Moving and scaled state features (see state_features.hpp).
#include "lfd_core/segmentation/state_features.hpp"

#include <algorithm>

#include "lfd_core/util/robust_statistics.hpp"

namespace lfd {

std::vector<std::string> movingStates(const std::vector<FeatureMatrix>& demos,
                                      const std::vector<std::string>& states) {
  std::vector<std::string> out;
  for (const std::string& name : states) {
    for (const FeatureMatrix& demo : demos) {
      const auto col = demo.data.col(demo.require(name));
      if (col.maxCoeff() - col.minCoeff() > 1e-12 * (1.0 + col.cwiseAbs().maxCoeff())) {
        out.push_back(name);
        break;
      }
    }
  }
  return out;
}

std::vector<std::string> selectedStates(const std::vector<std::string>& moving,
                                        const std::vector<std::string>& selected) {
  std::vector<std::string> out;
  for (const std::string& name : moving)
    if (std::find(selected.begin(), selected.end(), name) != selected.end()) out.push_back(name);
  return out;
}

std::vector<std::string> featuresAboveNoise(const std::vector<FeatureMatrix>& demos,
                                            const std::vector<std::string>& names,
                                            double min_range_sigmas) {
  std::vector<std::string> out;
  for (const std::string& name : names) {
    const bool moves = std::any_of(demos.begin(), demos.end(), [&](const FeatureMatrix& demo) {
      const Eigen::VectorXd col = demo.data.col(demo.require(name));
      if (col.size() == 0) return false;
      const double range = col.maxCoeff() - col.minCoeff();
      return range > 0.0 && range >= min_range_sigmas * measurementNoiseSigma(col);
    });
    if (moves) out.push_back(name);
  }
  return out;
}

std::vector<Eigen::MatrixXd> scaledStates(const std::vector<FeatureMatrix>& demos,
                                          const std::vector<std::string>& names) {
  std::vector<Eigen::MatrixXd> out;
  for (const FeatureMatrix& demo : demos) out.push_back(demo.select(names).data);
  for (Eigen::Index c = 0; c < static_cast<Eigen::Index>(names.size()); ++c) {
    double range = 0.0;
    for (const Eigen::MatrixXd& m : out)
      range = std::max(range, m.col(c).maxCoeff() - m.col(c).minCoeff());
    if (!(range > 0)) range = 1.0;
    for (Eigen::MatrixXd& m : out) m.col(c) = (m.col(c).array() - m.col(c).minCoeff()) / range;
  }
  return out;
}

}  // namespace lfd
