// MountCache: one lookup per frame, a failed lookup retried only after retry_seconds, capacity 1 keeping
// the latest frame only; LogThrottle: one line per key and period.
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <string_view>

#include "hglasm_odometry/ros/log_throttle.h"
#include "hglasm_odometry/ros/mount_cache.h"

namespace hglasm_odometry {
namespace {

using Cache = MountCache<double>;

/// A tf stand-in: the frames it knows, and how often it was asked.
struct FakeTf {
  std::map<std::string, double, std::less<>> mounts;
  int lookups = 0;
  bool operator()(std::string_view frame, double* mount) {
    ++lookups;
    const auto found = mounts.find(frame);
    if (found == mounts.end()) return false;
    *mount = found->second;
    return true;
  }
};

TEST(MountCache, LooksEachFrameUpOnce) {
  Cache cache;
  FakeTf tf;
  tf.mounts = {{"laser", 1.0}, {"imu", 2.0}};
  double mount = 0.0;
  EXPECT_EQ(cache.find("laser", 0.0, tf, &mount), Cache::Result::kFound);
  EXPECT_EQ(mount, 1.0);
  EXPECT_EQ(cache.find("imu", 0.0, tf, &mount), Cache::Result::kFound);
  EXPECT_EQ(cache.find("laser", 1.0, tf, &mount), Cache::Result::kCached);
  EXPECT_EQ(mount, 1.0);
  EXPECT_EQ(cache.find("imu", 1.0, tf, &mount), Cache::Result::kCached);
  EXPECT_EQ(mount, 2.0);
  EXPECT_EQ(tf.lookups, 2);
}

TEST(MountCache, AMissingFrameIsAskedForAgainOnlyAfterTheRetryPeriod) {
  Cache cache(0.05);
  FakeTf tf;
  double mount = 0.0;
  EXPECT_EQ(cache.find("imu", 10.0, tf, &mount), Cache::Result::kMissing);
  EXPECT_EQ(cache.find("imu", 10.01, tf, &mount), Cache::Result::kMissing);
  EXPECT_EQ(tf.lookups, 1);
  tf.mounts["imu"] = 3.0;
  EXPECT_EQ(cache.find("imu", 10.04, tf, &mount), Cache::Result::kMissing);
  EXPECT_EQ(cache.find("imu", 10.05, tf, &mount), Cache::Result::kFound);
  EXPECT_EQ(mount, 3.0);
  EXPECT_EQ(tf.lookups, 2);
}

TEST(MountCache, CapacityOneKeepsTheLatestFrameOnly) {
  Cache cache(0.0, 1);
  FakeTf tf;
  tf.mounts = {{"a", 1.0}, {"b", 2.0}};
  double mount = 0.0;
  EXPECT_EQ(cache.find("a", 0.0, tf, &mount), Cache::Result::kFound);
  EXPECT_EQ(cache.find("b", 0.0, tf, &mount), Cache::Result::kFound);
  EXPECT_EQ(cache.find("b", 0.0, tf, &mount), Cache::Result::kCached);
  EXPECT_EQ(cache.find("a", 0.0, tf, &mount), Cache::Result::kFound);  // looked up again
  EXPECT_EQ(mount, 1.0);
  EXPECT_EQ(tf.lookups, 3);
}

TEST(LogThrottle, OneLinePerKeyAndPeriod) {
  LogThrottle throttle;
  EXPECT_TRUE(throttle.allow("tf", 100.0, 5.0));
  EXPECT_FALSE(throttle.allow("tf", 104.9, 5.0));
  EXPECT_TRUE(throttle.allow("odom", 104.9, 5.0));  // another key
  EXPECT_TRUE(throttle.allow("tf", 105.0, 5.0));
  EXPECT_FALSE(throttle.allow("tf", 109.0, 5.0));  // counted from the last line let through
}

}  // namespace
}  // namespace hglasm_odometry
