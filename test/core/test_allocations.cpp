// Heap allocations of the per-scan work in the steady state: matching a scan (GA, MbICP, the leap test's
// judge, the learners) reuses the memory of the scans before it. This binary's operator new counts the
// allocations of the thread that asks it to (only the tests here do).
#include <gtest/gtest.h>

#include <cstdlib>
#include <new>

#include "hglasm_odometry/core/odometry_pipeline.h"
#include "test_util.h"

namespace {

thread_local bool counting = false;
thread_local std::size_t allocations = 0;

/// Counts this thread's allocations while alive.
class AllocationCounter {
 public:
  AllocationCounter() {
    allocations = 0;
    counting = true;
  }
  ~AllocationCounter() { counting = false; }
  std::size_t count() const { return allocations; }
};

void* allocate(std::size_t size) {
  if (counting) ++allocations;
  while (true) {
    if (void* memory = std::malloc(size == 0 ? 1 : size)) return memory;
    const std::new_handler handler = std::get_new_handler();
    if (!handler) throw std::bad_alloc();
    handler();
  }
}
void* allocate(std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return allocate(size);
  } catch (...) {
    return nullptr;
  }
}
}  // namespace

// Every unaligned form is replaced, so that memory from any of them is freed by the matching one here (the
// aligned forms stay the library's, or the sanitizers', and pair among themselves).
void* operator new(std::size_t size) { return allocate(size); }
void* operator new[](std::size_t size) { return allocate(size); }
void* operator new(std::size_t size, const std::nothrow_t& tag) noexcept { return allocate(size, tag); }
void* operator new[](std::size_t size, const std::nothrow_t& tag) noexcept { return allocate(size, tag); }
void operator delete(void* memory) noexcept { std::free(memory); }
void operator delete[](void* memory) noexcept { std::free(memory); }
void operator delete(void* memory, std::size_t) noexcept { std::free(memory); }
void operator delete[](void* memory, std::size_t) noexcept { std::free(memory); }
void operator delete(void* memory, const std::nothrow_t&) noexcept { std::free(memory); }
void operator delete[](void* memory, const std::nothrow_t&) noexcept { std::free(memory); }

namespace {

TEST(Allocations, AStandingRobotsScansAllocateOnlyTheConvertedScanHandedToTheCaller) {
  // A robot standing in the room, wheels and scans at 10 Hz: every scan is matched (GA, MbICP, the leap
  // test's judge, the noise learner), none is a keyframe after the first.
  const hglasm::Pose2D pose = hglasm_test::rawPose(0.3, -0.2, 0.4);
  const hglasm::RangeScan ranges =
      hglasm_test::simulateRanges(hglasm_test::room(), pose, hglasm_test::halfCircleLaser());
  hglasm::OdometryPipeline pipeline;
  std::size_t scans_matched = 0, keyframes = 0;
  const auto process = [&](int k) {
    const double stamp = 0.1 * k;
    pipeline.addOdometry(stamp, pose);
    const hglasm::PipelineUpdate update = pipeline.processScan(stamp, ranges);
    scans_matched += update.tracker.matched ? 1 : 0;
    keyframes += update.tracker.new_keyframe ? 1 : 0;
  };
  for (int k = 0; k < 20; ++k) process(k);  // the buffers grow to their size
  scans_matched = keyframes = 0;
  constexpr int kScans = 30;
  std::size_t counted = 0;
  {
    const AllocationCounter counter;
    for (int k = 20; k < 20 + kScans; ++k) process(k);
    counted = counter.count();
  }
  ASSERT_EQ(scans_matched, static_cast<std::size_t>(kScans));
  ASSERT_EQ(keyframes, 0u);
  // Fewer than 3 per scan: the converted scan (its points and their beam indices) travels in the update to
  // the caller, and the wheels' samples and the recent poses are deques (a block now and then). Matching
  // allocated six more per scan before its buffers were kept (the GA's populations, the judge's points, the
  // noise learner's window): 244 calls in these 30 scans, 64 after.
  EXPECT_LT(counted, 3u * kScans) << counted << " allocations in " << kScans << " scans";
}

}  // namespace
