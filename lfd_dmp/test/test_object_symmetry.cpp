// Symmetric objects described as the demonstrations saw them (lfd_dmp/object_symmetry.hpp).
#include "lfd_dmp/object_symmetry.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace {

lfd::Pose yawed(double yaw, const Eigen::Vector3d& at = Eigen::Vector3d(0.5, 0.0, 0.8)) {
  return {at, Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()))};
}

// Two demos saw the block turned 0.1 and 0.2 rad, and the mug upright.
lfd_dmp::SkillLibrary demonstrated() {
  lfd_dmp::SkillLibrary lib;
  for (double yaw : {0.1, 0.2}) {
    lfd_dmp::DemoScene d;
    d.scene.objects["block"] = yawed(yaw);
    d.scene.objects["mug"] = yawed(0.0);
    lib.demo_scenes["demo_" + std::to_string(yaw)] = d;
  }
  return lib;
}

TEST(ObjectSymmetry, TurnsAboutTheAxesCloseIntoTheObjectsGroup) {
  EXPECT_EQ(lfd_dmp::symmetryOfOrders(4, 4, 4).rotations.size(), 24u);  // a cube
  EXPECT_EQ(lfd_dmp::symmetryOfOrders(4, 2, 2).rotations.size(), 8u);   // a square bar along x
  EXPECT_EQ(lfd_dmp::symmetryOfOrders(1, 1, 2).rotations.size(), 2u);
  EXPECT_EQ(lfd_dmp::symmetryOfOrders(1, 1, 1).rotations.size(), 1u);
  EXPECT_THROW(lfd_dmp::symmetryOfOrders(5, 1, 1), std::invalid_argument);
  EXPECT_THROW(lfd_dmp::symmetryOfOrders(3, 4, 1), std::invalid_argument);  // not finite
}

// A cube that landed turned 90 deg (or on its side) is the cube the demos saw; its position and
// any object without a declared symmetry stay as measured.
TEST(ObjectSymmetry, ASymmetricObjectIsDescribedAsTheDemonstrationsSawIt) {
  const lfd_dmp::SkillLibrary lib = demonstrated();
  const auto cube = lfd_dmp::symmetryOfOrders(4, 4, 4);
  const lfd::Pose turned = yawed(0.15 + M_PI / 2);
  const lfd::Pose canonical = lfd_dmp::canonicalPose(lib, "block", turned, cube);
  EXPECT_NEAR(canonical.orientation.angularDistance(yawed(0.15).orientation), 0.0, 1e-9);
  EXPECT_EQ(canonical.position, turned.position);
  lfd::Pose on_its_side = yawed(0.1);
  on_its_side.orientation = on_its_side.orientation * Eigen::Quaterniond(Eigen::AngleAxisd(
                                                          M_PI / 2, Eigen::Vector3d::UnitX()));
  EXPECT_LT(lfd_dmp::canonicalPose(lib, "block", on_its_side, cube)
                .orientation.angularDistance(yawed(0.1).orientation),
            1e-9);
  lfd::Scene scene;
  scene.objects["block"] = turned;
  scene.objects["mug"] = yawed(M_PI);
  const lfd::Scene out = lfd_dmp::canonicalScene(lib, scene, {{"block", cube}});
  EXPECT_LT(out.objects.at("block").orientation.angularDistance(yawed(0.15).orientation), 1e-9);
  EXPECT_LT(out.objects.at("mug").orientation.angularDistance(yawed(M_PI).orientation), 1e-12);
  // Not in any demo scene: as measured.
  EXPECT_LT(lfd_dmp::canonicalPose(lib, "stick", turned, cube)
                .orientation.angularDistance(turned.orientation),
            1e-12);
}

}  // namespace
