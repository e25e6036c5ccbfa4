// The gyro prior at the ROS level (imu.test, issue 14 item 3). This node drives three laser-odometry
// nodelets with the same simulated robot: a 5 Hz laser on a robot that drives a 1.5 m square and spins on
// the spot at 180 deg/s at each corner, with wheels that count 30 % of every turn, and an IMU mounted nearly
// upside down, pitched and yawed on the base (so its rate reaches the base only through tf), with a bias
// and white noise.
//   /odo_g: use_imu, the IMU's angular velocity;  /odo_o: use_imu with imu/use_orientation;
//   /odo_w: the wheels alone (use_imu false).
// The IMU-fed instances track the spins that the wheels alone lose; when the IMU stops for two seconds
// /odo_g warns once, predicts the rotation from the wheels, and says when the IMU is back.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <memory>

#include <sensor_msgs/Imu.h>

#include "simulated_robot.h"

namespace hglasm_odometry {
namespace {

using namespace rostest_sim;  // NOLINT: the shared simulated robot of the rostests

constexpr double kScanPeriod = 0.2;         // s: a 5 Hz laser
constexpr double kTurnRate = M_PI;          // rad/s at the corners
constexpr double kWheelTurnScale = 0.3;     // the wheels count 30 % of every turn
constexpr double kImuPeriod = 0.005;        // s: 200 Hz
constexpr double kImuBias = 0.03;           // rad/s (1.7 deg/s): six times the default prior's, learned
constexpr double kImuNoiseDensity = 0.005;  // rad/s per sqrt(Hz)
constexpr double kLap = 4.0 * (3.0 + M_PI / 2 / kTurnRate);  // s: one lap of the square, 14 s

/// The IMU frame's rotation in the base frame: rolled by 2.5 rad (nearly upside down), pitched by 0.4 rad
/// and yawed by 0.7 rad, so the base's yaw rate reaches it on all three axes, and the inverse rotation
/// would give back only an eighth of it (a half-turn mount would be its own inverse).
Eigen::Quaterniond imuMount() {
  return Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()) *
                            Eigen::AngleAxisd(2.5, Eigen::Vector3d::UnitX()));
}

geometry_msgs::Quaternion toMsg(const Eigen::Quaterniond& q) {
  geometry_msgs::Quaternion msg;
  msg.w = q.w();
  msg.x = q.x();
  msg.y = q.y();
  msg.z = q.z();
  return msg;
}

/// The IMU of the simulated robot, published: the gyro's yaw rate (simulated_robot.h: bias, seeded noise)
/// seen in the IMU's frame, and the orientation (the base's yaw composed with the mount).
class ImuPublisher {
 public:
  ImuPublisher(ros::NodeHandle& nh, const std::string& topic, std::string frame,
               hglasm_test::SimulatedRobot& sim)
      : pub_(nh.advertise<sensor_msgs::Imu>(topic, 2000)), frame_(std::move(frame)), sim_(sim) {
    hglasm_test::GyroSpec gyro;
    gyro.period = kImuPeriod;
    gyro.bias = kImuBias;
    gyro.noise_density = kImuNoiseDensity;
    gyro.seed = 11;
    gyro.pairs_within_call = true;
    sim_.enableGyro(gyro);
  }

  bool connected() const { return pub_.getNumSubscribers() > 0; }

  /// Samples up to simulated time t; with `silent`, none are sent (the IMU stalled) but time goes on.
  void publishUntil(double t, bool silent = false) {
    hglasm_test::RobotSink sink;
    if (!silent) sink.gyro = [this](double time, double yaw_rate) { publish(time, yaw_rate); };
    sim_.advanceGyro(t, sink);
  }

 private:
  void publish(double time, double yaw_rate) {
    const Eigen::Quaterniond base(Eigen::AngleAxisd(sim_.truth(time).theta, Eigen::Vector3d::UnitZ()));
    const Eigen::Vector3d rate = imuMount().inverse() * Eigen::Vector3d(0.0, 0.0, yaw_rate);
    sensor_msgs::Imu msg;
    msg.header.stamp = ros::Time(kStampOrigin + time);
    msg.header.frame_id = frame_;
    msg.angular_velocity.x = rate.x();
    msg.angular_velocity.y = rate.y();
    msg.angular_velocity.z = rate.z();
    msg.orientation = toMsg(base * imuMount());
    msg.orientation_covariance[0] = msg.angular_velocity_covariance[0] = 1e-4;
    pub_.publish(msg);
  }

  ros::Publisher pub_;
  std::string frame_;
  hglasm_test::SimulatedRobot& sim_;
};

struct Instance {
  std::unique_ptr<Robot> robot;
  std::unique_ptr<ImuPublisher> imu;                     // null for the wheels-only instance
  double worst_translation = 0.0, worst_rotation = 0.0;  // of every pose since the start
  int rotations_from_imu = 0, leaps = 0, resets = 0;
  double imu_bias = 0.0;  // as the last ~match published it
};

/// The three instances, their static tf, and what they publish on /rosout.
struct ImuScene {
  ros::NodeHandle nh;
  Recorder recorder;
  ros::Subscriber log_sub = nh.subscribe("/rosout", 10000, &Recorder::onLog, &recorder);
  tf2_ros::StaticTransformBroadcaster static_tf;
  Instance g, o, w;
  double t = 0.0;

  ImuScene() {
    const Path path = hglasm_test::squareWithSpins(kTurnRate);
    for (auto* entry : {&g, &o, &w}) {
      const std::string id = entry == &g ? "g" : entry == &o ? "o" : "w";
      entry->robot = std::make_unique<Robot>(
          nh,
          RobotSetup{"/odo_" + id, "/" + id + "/scan", "/" + id + "/wheel_odom", "odom_" + id, "base_" + id,
                     "laser_" + id, Pose2D(0.1, 0.0, 0.0), path, hglasm_test::halfCircleLaser()});
      entry->robot->setWheelTurnScale(kWheelTurnScale);
      if (entry != &w) {
        entry->imu = std::make_unique<ImuPublisher>(nh, "/" + id + "/imu", "imu_" + id, entry->robot->sim());
      }
    }
  }

  void sendTf() {
    std::vector<geometry_msgs::TransformStamped> transforms;
    for (auto* entry : {&g, &o, &w}) {
      const RobotSetup& setup = entry->robot->setup();
      geometry_msgs::TransformStamped laser;
      laser.header.stamp = ros::Time(kStampOrigin);
      laser.header.frame_id = setup.base_frame;
      laser.child_frame_id = setup.laser_frame;
      laser.transform = transformMsgFromPose2D(setup.mount);
      transforms.push_back(laser);
      if (!entry->imu) continue;
      geometry_msgs::TransformStamped imu = laser;
      imu.child_frame_id = "imu_" + setup.base_frame.substr(5);
      imu.transform = geometry_msgs::Transform();
      imu.transform.rotation = toMsg(imuMount());
      transforms.push_back(imu);
    }
    static_tf.sendTransform(transforms);
  }

  bool connected() {
    for (auto* entry : {&g, &o, &w}) {
      if (!entry->robot->connected() || (entry->imu && !entry->imu->connected())) return false;
    }
    return true;
  }
};
ImuScene* scene = nullptr;  // created in main() after ros::init

/// The next scan of every instance (the IMU's samples and the wheels' first, a little past it); each
/// instance's pose is compared with the truth since the start. `g_imu_silent`: /odo_g's IMU sends nothing.
void stepAll(bool g_imu_silent = false) {
  ImuScene& s = *scene;
  s.t += kScanPeriod;
  s.g.imu->publishUntil(s.t + 0.02, g_imu_silent);
  s.o.imu->publishUntil(s.t + 0.02);
  for (Instance* entry : {&s.g, &s.o, &s.w}) {
    Match match;
    nav_msgs::Odometry odom;
    Robot& robot = *entry->robot;
    ASSERT_TRUE(scanStep(robot, s.t, &match, &odom)) << robot.setup().instance << " at " << s.t;
    const Pose2D expected = hglasm_test::relativeByHand(robot.truth(0.0), robot.truth(s.t));
    const Pose2D got = pose2D(odom.pose.pose);
    entry->worst_translation =
        std::max(entry->worst_translation, hglasm_test::translationError(got, expected));
    entry->worst_rotation = std::max(entry->worst_rotation, hglasm_test::rotationError(got, expected));
    entry->rotations_from_imu += match.rotation_from_imu;
    entry->leaps += match.leap;
    entry->resets += match.reset;
    entry->imu_bias = match.imu_bias;
  }
}

void report(const char* what, const Instance& entry) {
  std::printf("%s %s: worst %.4f m %.3f deg, leaps %d, IMU rotations %d, resets %d, IMU bias %.4f rad/s\n",
              what, entry.robot->setup().instance.c_str(), entry.worst_translation,
              entry.worst_rotation * 180.0 / M_PI, entry.leaps, entry.rotations_from_imu, entry.resets,
              entry.imu_bias);
}

TEST(ImuRos, FastTurnsAreTrackedWithTheImuAndOnlyLeapByLeapWithTheSlippingWheels) {
  ImuScene& s = *scene;
  ASSERT_TRUE(waitFor([&] { return s.connected(); }, 20.0)) << "the three nodelets did not connect";
  s.sendTf();
  ros::WallDuration(1.0).sleep();  // for the nodelets' tf listeners
  s.t = -kScanPeriod;
  const int steps = static_cast<int>(std::lround(kLap / kScanPeriod));  // the first starts the odometry
  for (int i = 0; i <= steps; ++i) ASSERT_NO_FATAL_FAILURE(stepAll());
  for (const Instance* entry : {&s.g, &s.o, &s.w}) report("one lap", *entry);
  for (const Instance* entry : {&s.g, &s.o}) {
    const std::string& name = entry->robot->setup().instance;
    EXPECT_EQ(entry->rotations_from_imu, steps) << name << ": every step's rotation from the IMU";
    EXPECT_EQ(entry->resets, 1) << name;
    EXPECT_EQ(entry->leaps, 0) << name;
    EXPECT_LT(entry->worst_translation, 0.03) << name;
    EXPECT_LT(entry->worst_rotation, deg(0.5)) << name;
  }
  EXPECT_NEAR(s.g.imu_bias, kImuBias, 0.01) << "/odo_g publishes the bias it learned on ~match";
  EXPECT_EQ(s.w.rotations_from_imu, 0);
  // The wheels alone miss 70 % of every spin: only leaps (each needing the scan's evidence to outweigh the
  // odds against it) keep that nodelet on track, at nearly every spin.
  EXPECT_GE(s.w.leaps, 5) << "the wheels alone were expected to need a leap at the spins";
}

TEST(ImuRos, AStalledImuFallsBackToTheWheelsWithOneWarningAndIsTakenBackWhenItReturns) {
  ImuScene& s = *scene;
  ASSERT_GT(s.t, kLap - 1.0) << "runs after the first lap (the first test)";
  // The second lap's first side is straight for 3 s: the IMU stalls for 2 s of it (a gap far beyond
  // imu/max_gap), then returns before the next spin.
  const std::size_t logs_before = s.recorder.logCount();
  const int imu_before = s.g.rotations_from_imu;
  for (int i = 0; i < 2; ++i) ASSERT_NO_FATAL_FAILURE(stepAll());
  for (int i = 0; i < 10; ++i) ASSERT_NO_FATAL_FAILURE(stepAll(true));
  const int imu_while_stalled = s.g.rotations_from_imu - imu_before;
  for (int i = 0; i < 58; ++i) ASSERT_NO_FATAL_FAILURE(stepAll());  // to the end of the second lap
  ros::WallDuration(0.5).sleep();                                   // for rosout
  report("two laps", s.g);

  // The last sample before the stall is 0.02 s past the second scan; the first step after the stall starts
  // inside the gap: 2 steps with the IMU, then 10 + 1 without.
  EXPECT_EQ(imu_while_stalled, 2);
  EXPECT_EQ(s.g.rotations_from_imu - imu_before, 70 - 11) << "the IMU taken back after the stall";
  const std::vector<std::string> warnings = s.recorder.lines("/odo_g", rosgraph_msgs::Log::WARN, logs_before);
  ASSERT_EQ(warnings.size(), 1u) << joined(warnings);
  EXPECT_NE(warnings[0].find("no IMU data on /g/imu"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("the wheel odometry"), std::string::npos) << warnings[0];
  bool back = false;
  for (const std::string& line : s.recorder.lines("/odo_g", rosgraph_msgs::Log::INFO, logs_before)) {
    back = back || line.find("IMU data on /g/imu again") != std::string::npos;
  }
  EXPECT_TRUE(back) << "no log line that the IMU is back";
  EXPECT_EQ(s.g.resets, 1);
  EXPECT_EQ(s.g.leaps, 0);
  EXPECT_LT(s.g.worst_translation, 0.03);
  EXPECT_LT(s.g.worst_rotation, deg(0.5));
  EXPECT_TRUE(s.recorder.lines("/odo_o", rosgraph_msgs::Log::WARN, logs_before).empty())
      << "/odo_o's IMU never stalled";
}

}  // namespace
}  // namespace hglasm_odometry

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "imu_rostest");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  int result = 0;
  {
    hglasm_odometry::ImuScene scene;
    hglasm_odometry::scene = &scene;
    result = RUN_ALL_TESTS();
    hglasm_odometry::scene = nullptr;
  }
  spinner.stop();
  return result;
}
