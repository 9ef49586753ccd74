// The registry of segmentation methods (segmentation_method.hpp).
#include "lfd_core/segmentation/segmentation_method.hpp"

#include <functional>
#include <stdexcept>
#include <utility>

#include "lfd_core/segmentation/joint_segmentation.hpp"
#include "lfd_core/segmentation/paper_segmentation.hpp"
#include "lfd_core/segmentation/zone_search_segmentation.hpp"

namespace lfd {

SegmentationMethod::~SegmentationMethod() = default;

namespace {

// Procedure "joint" (joint_segmentation.hpp). Its own consensus is the agreement of the aligned
// demos' evidence, so the wrapper only forwards.
class JointSegmentation : public SegmentationMethod {
 public:
  std::string name() const override { return "joint"; }
  SegmentationPipelineResult segment(const PreparedSegmentation& prepared,
                                     const std::vector<FeatureMatrix>& demos,
                                     const SegmentationPipelineConfig& config) const override {
    return segmentJointly(prepared, demos, config);
  }
};

using Factory = std::function<std::unique_ptr<SegmentationMethod>()>;

template <typename Method>
std::pair<std::string, Factory> entry() {
  return {Method().name(), [] { return std::make_unique<Method>(); }};
}

// One line per method; the order is the one names are listed in.
const std::vector<std::pair<std::string, Factory>>& registry() {
  static const std::vector<std::pair<std::string, Factory>> kMethods = {
      entry<ZoneSearchSegmentation>(), entry<PaperSegmentation>(), entry<JointSegmentation>()};
  return kMethods;
}

}  // namespace

std::vector<std::string> segmentationMethodNames() {
  std::vector<std::string> names;
  for (const auto& [name, factory] : registry()) names.push_back(name);
  return names;
}

std::unique_ptr<SegmentationMethod> makeSegmentationMethod(const std::string& name) {
  std::string known;
  for (const auto& [method, factory] : registry()) {
    if (method == name) return factory();
    known += (known.empty() ? "" : ", ") + method;
  }
  throw std::invalid_argument("unknown segmentation method '" + name + "' (" + known + ")");
}

}  // namespace lfd
