// BearingBins: the search finds what a brute-force pass over every point and segment finds, for points
// and segments anywhere around the origin (across the +-pi seam, next to the origin, far away), whatever
// the starting bound, with and without a bearing window.
#include "hglasm_odometry/core/bearing_bins.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "test_util.h"

namespace {

using Eigen::Vector2d;
using hglasm::BearingBins;

constexpr double kL = 3.0;

/// MbICP's d_ap^2 of p to a reference point q, written out (the rotation linearised at q).
double dap(const Vector2d& p, const Vector2d& q) {
  const Vector2d d = p - q;
  const double cross = d.x() * q.y() - d.y() * q.x();
  return d.squaredNorm() - cross * cross / (q.squaredNorm() + kL * kL);
}

/// Any point of a segment is a candidate the search must not miss: here its closest point to p.
double dapToSegment(const Vector2d& p, const Vector2d& a, const Vector2d& b) {
  const Vector2d e = b - a;
  const double t = std::clamp((p - a).dot(e) / e.squaredNorm(), 0.0, 1.0);
  return dap(p, a + t * e);
}

struct Reference {
  std::vector<Vector2d> points;
  std::vector<std::int8_t> has_next;
};

/// Scans of random walls seen from several origins (a local map), plus stray points.
Reference randomReference(std::mt19937* rng, double scale) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Reference reference;
  for (int scan = 0; scan < 5; ++scan) {
    const Vector2d origin(unit(*rng), unit(*rng));
    const double start = hglasm_test::kPi * unit(*rng);
    const int beams = 90;
    for (int i = 0; i < beams; ++i) {
      const double angle = start + i * hglasm_test::deg(2.0);
      const double range = scale * (1.0 + 0.5 * std::sin(3.0 * angle) + 0.05 * unit(*rng));
      reference.points.push_back(origin + range * Vector2d(std::cos(angle), std::sin(angle)));
      reference.has_next.push_back(i + 1 < beams && unit(*rng) > -0.8 ? 1 : 0);
    }
  }
  for (int i = 0; i < 20; ++i) {
    reference.points.emplace_back(scale * unit(*rng), scale * unit(*rng));
    reference.has_next.push_back(0);
  }
  reference.points.emplace_back(1e-9, -1e-9);  // next to the origin: no bearing
  reference.has_next.push_back(0);
  return reference;
}

/// The best of every element within `window` of p's bearing (a point's bearing; a segment's if either end
/// point's is).
double bruteForce(const Reference& reference, const Vector2d& p, double best, double window) {
  const auto within = [&](const Vector2d& q) {
    const double offset =
        std::abs(hglasm_test::angleDiff(std::atan2(q.y(), q.x()), std::atan2(p.y(), p.x())));
    return window >= hglasm_test::kPi || q.norm() < 1e-6 || offset <= window;
  };
  for (std::size_t i = 0; i < reference.points.size(); ++i) {
    const Vector2d& a = reference.points[i];
    if (within(a)) best = std::min(best, dap(p, a));
    if (i + 1 < reference.points.size() && reference.has_next[i]) {
      const Vector2d& b = reference.points[i + 1];
      if (within(a) || within(b)) best = std::min(best, dapToSegment(p, a, b));
    }
  }
  return best;
}

double searched(BearingBins* bins, const Reference& reference, const Vector2d& p, double best) {
  bins->search(p, &best, -1, [&](int i, bool segment) {
    const Vector2d& a = reference.points[i];
    best = std::min(best, segment ? dapToSegment(p, a, reference.points[i + 1]) : dap(p, a));
  });
  return best;
}

TEST(BearingBins, FindsWhatBruteForceFinds) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  BearingBins bins;
  int checked = 0, found = 0;
  for (double scale : {0.5, 3.0, 20.0}) {
    for (int trial = 0; trial < 4; ++trial) {
      const Reference reference = randomReference(&rng, scale);
      bins.build(reference.points, reference.has_next);
      for (const double window : {hglasm_test::kPi, 0.52}) {
        bins.setMetric(kL * kL, window);
        for (int query = 0; query < 500; ++query) {
          const Vector2d p = query % 50 == 0 ? Vector2d(1e-10, 0.0)
                                             : Vector2d(1.5 * scale * unit(rng), 1.5 * scale * unit(rng));
          const double gate_sq = std::pow(10.0, -4.0 + 3.5 * (0.5 + 0.5 * unit(rng)));
          const double expected = bruteForce(reference, p, gate_sq, window);
          const double result = searched(&bins, reference, p, gate_sq);
          ++checked;
          found += expected < gate_sq;
          EXPECT_EQ(result, expected) << "p " << p.transpose() << " scale " << scale << " window " << window;
        }
      }
    }
  }
  EXPECT_GT(found, checked / 4);  // the queries do find things
}

TEST(BearingBins, BinOfAgreesWithAtan2AcrossTheSeam) {
  BearingBins bins;
  std::vector<Vector2d> points(1000, Vector2d(1.0, 0.0));
  bins.build(points, std::vector<std::int8_t>(points.size(), 0));
  const int count = static_cast<int>(bins.binCount());
  for (int k = 0; k < 100000; ++k) {
    const double angle = -hglasm_test::kPi + 2.0 * hglasm_test::kPi * (k + 0.5) / 100000;
    const Vector2d p(std::cos(angle), std::sin(angle));
    const double position = (std::atan2(p.y(), p.x()) + hglasm_test::kPi) / (2.0 * hglasm_test::kPi) * count;
    const int bin = bins.binOf(p);
    // Within a hair of an edge either side is right.
    if (std::abs(position - std::round(position)) > 1e-9) {
      EXPECT_EQ(bin, static_cast<int>(position) % count);
    }
  }
}

TEST(BearingBins, EmptyAndNonFinite) {
  BearingBins bins;
  double best = 1.0;
  int visits = 0;
  bins.search(Vector2d(1.0, 2.0), &best, -1, [&](int, bool) { ++visits; });
  EXPECT_EQ(visits, 0);
  bins.build({Vector2d(1.0, 0.0), Vector2d(1.0, 0.1)}, {1, 0});
  bins.search(Vector2d(std::nan(""), 0.0), &best, -1, [&](int, bool) { ++visits; });
  EXPECT_EQ(visits, 0);
  bins.setMetric(kL * kL, hglasm_test::kPi);
  bins.search(Vector2d(1.0, 0.05), &best, -1, [&](int, bool) { ++visits; });
  EXPECT_GT(visits, 0);
}

}  // namespace
