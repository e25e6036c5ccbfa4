// The nodelet hglasm_odometry/LaserOdometryNodelet: loads and validates the parameters, then runs
// LaserOdometry. With invalid parameters it logs one error naming the parameter and stays inert (no
// subscriptions, no publications): a nodelet cannot unload itself, so fix the parameters and reload it.
#include <memory>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include "hglasm_odometry/ros/laser_odometry.h"
#include "hglasm_odometry/ros/parameters.h"

namespace hglasm_odometry {

class LaserOdometryNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    LaserOdometryOptions options;
    std::string error;
    std::vector<std::string> warnings;
    const bool valid = loadOptions(getPrivateNodeHandle(), &options, &error, &warnings);
    for (const std::string& warning : warnings) NODELET_WARN_STREAM(warning);
    if (!valid) {
      NODELET_ERROR_STREAM(error << "; laser odometry NOT started (nothing subscribed or published)");
      return;
    }
    odometry_ = std::make_unique<LaserOdometry>(getNodeHandle(), getPrivateNodeHandle(), options);
  }

  std::unique_ptr<LaserOdometry> odometry_;
};

}  // namespace hglasm_odometry

PLUGINLIB_EXPORT_CLASS(hglasm_odometry::LaserOdometryNodelet, nodelet::Nodelet)
