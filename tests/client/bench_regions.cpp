// One frame = 1,000 objects x 8 hull vertices: projection + outer + inner + assessment.
// Unscented (default) vs the linear fast path vs a 1,000-sample Monte Carlo of the same
// frame. Single thread. Run: build/tests/client/bench_regions
#include <cmath>
#include <cstdio>
#include <numbers>
#include <map>
#include <random>
#include <string>

#include <benchmark/benchmark.h>

#include <Eigen/Cholesky>

#include "bench_frame.hpp"
#include "covtrack/client/regions.hpp"

using namespace covtrack;
using namespace covtrack::client;

namespace {

using Frame = test::BenchFrame;

const Frame& frame() {
  static const Frame f = test::make_bench_frame(1000);
  return f;
}

// As an application runs it: one ObjectRegions kept per object, recomputed every frame.
void run_frame(benchmark::State& state, ProjectionMethod method, bool whole_object = true) {
  const Frame& f = frame();
  ObjectRegionOptions o;
  o.projection.method = method;
  o.regions.whole_object = whole_object;
  std::vector<ObjectRegions> regions(f.poses.size());
  for (auto _ : state) {
    for (std::size_t i = 0; i < f.poses.size(); ++i) {
      compute_object_regions(f.camera, f.poses[i], f.vertices[i], o, regions[i]);
      benchmark::DoNotOptimize(regions[i].assessment);
    }
  }
  state.counters["objects"] = double(f.poses.size());
}

void BM_FrameUnscented(benchmark::State& state) { run_frame(state, ProjectionMethod::unscented); }
void BM_FrameLinear(benchmark::State& state) { run_frame(state, ProjectionMethod::linear); }
// The outer region at one vertex's scale (RegionOptions::whole_object false): what the
// whole-object scale costs.
void BM_FrameUnscentedPerVertexScale(benchmark::State& state) {
  run_frame(state, ProjectionMethod::unscented, false);
}
void BM_FrameLinearPerVertexScale(benchmark::State& state) { run_frame(state, ProjectionMethod::linear, false); }

// The frame with every object's rotation error 8 degrees on each axis (the frame's are 1-5):
// the fifth-degree cubature (the default there) against the unscented transform.
void strong_rotation_frame(benchmark::State& state, double cubature_min_rotation_trace_rad2) {
  static const Frame f = [] {
    Frame rotated = frame();
    for (auto& pose : rotated.poses) {
      pose.covariance.bottomRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * std::pow(8 * std::numbers::pi / 180, 2);
      pose.covariance.topRightCorner<3, 3>().setZero();
      pose.covariance.bottomLeftCorner<3, 3>().setZero();
    }
    return rotated;
  }();
  ObjectRegionOptions o;
  o.projection.unscented.cubature_min_rotation_trace_rad2 = cubature_min_rotation_trace_rad2;
  std::vector<ObjectRegions> regions(f.poses.size());
  for (auto _ : state)
    for (std::size_t i = 0; i < f.poses.size(); ++i) {
      compute_object_regions(f.camera, f.poses[i], f.vertices[i], o, regions[i]);
      benchmark::DoNotOptimize(regions[i].assessment);
    }
}
void BM_FrameEightDegreesCubature(benchmark::State& state) { strong_rotation_frame(state, kCubatureMinRotationTraceRad2); }
void BM_FrameEightDegreesUnscented(benchmark::State& state) { strong_rotation_frame(state, INFINITY); }

// The same regions from sample covariances of 1,000 sampled poses per object.
void BM_FrameMonteCarlo1000(benchmark::State& state) {
  const Frame& f = frame();
  const RegionOptions ro;
  const Assessment assessment = default_assessment();
  std::mt19937_64 rng(2);
  std::normal_distribution<double> normal;
  constexpr int kSamples = 1000;
  for (auto _ : state) {
    for (std::size_t i = 0; i < f.poses.size(); ++i) {
      const auto& verts = f.vertices[i];
      const Mat6 L = Eigen::LLT<Mat6>(f.poses[i].covariance).matrixL();
      std::vector<Vec2> sum(verts.size(), Vec2::Zero());
      std::vector<Mat2> second(verts.size(), Mat2::Zero());
      for (int s = 0; s < kSamples; ++s) {
        Vec6 z;
        for (int k = 0; k < 6; ++k) z[k] = normal(rng);
        const Pose T = f.poses[i].T * se3_exp(L * z);
        for (std::size_t v = 0; v < verts.size(); ++v) {
          const Vec2 px = f.camera.project(T * verts[v]);
          sum[v] += px;
          second[v] += px * px.transpose();
        }
      }
      std::vector<ProjectedVertex> pv(verts.size());
      for (std::size_t v = 0; v < verts.size(); ++v) {
        pv[v].mean_px = sum[v] / kSamples;
        pv[v].covariance_px2 =
            (second[v] - kSamples * pv[v].mean_px * pv[v].mean_px.transpose()) / (kSamples - 1);
      }
      std::vector<Vec2> means;
      for (const auto& v : pv) means.push_back(v.mean_px);
      std::vector<ProjectedVertex> hull;
      for (int h : convex_hull_indices(means)) hull.push_back(pv[h]);
      Polygon outer = expand_region(pv, ro);
      Polygon inner = contract_region(hull, ro);
      double a = assess(assessment, hull);
      benchmark::DoNotOptimize(outer.data());
      benchmark::DoNotOptimize(inner.data());
      benchmark::DoNotOptimize(a);
    }
  }
}

// Where the time goes: projection alone (UT), no regions.
void BM_FrameProjectionOnlyUnscented(benchmark::State& state) {
  const Frame& f = frame();
  std::vector<std::vector<ProjectedVertex>> projected(f.poses.size());
  for (auto _ : state)
    for (std::size_t i = 0; i < f.poses.size(); ++i) {
      project_vertices(f.camera, f.poses[i], f.vertices[i], {}, projected[i]);
      benchmark::DoNotOptimize(projected[i].data());
    }
}

// Where the time goes: each region step alone, on the frame's projected vertices.
const std::vector<std::vector<ProjectedVertex>>& projected_frame() {
  static const auto projected = [] {
    std::vector<std::vector<ProjectedVertex>> out;
    const Frame& f = frame();
    for (std::size_t i = 0; i < f.poses.size(); ++i)
      out.push_back(project_vertices(f.camera, f.poses[i], f.vertices[i]));
    return out;
  }();
  return projected;
}

void BM_FrameOuterOnly(benchmark::State& state) {
  const RegionOptions ro;
  std::size_t corners = 0;
  std::vector<Polygon> outer(projected_frame().size());
  for (auto _ : state) {
    corners = 0;
    for (std::size_t i = 0; i < outer.size(); ++i) {
      expand_region(projected_frame()[i], ro, outer[i]);
      corners += outer[i].size();
      benchmark::DoNotOptimize(outer[i].data());
    }
  }
  // Each corner costs one support evaluation over all the object's ellipses.
  state.counters["corners_per_object"] = double(corners) / projected_frame().size();
}

void BM_FrameInnerOnly(benchmark::State& state) {
  const RegionOptions ro;
  std::vector<std::vector<ProjectedVertex>> hulls;
  for (const auto& vertices : projected_frame()) {
    std::vector<Vec2> means;
    for (const auto& v : vertices) means.push_back(v.mean_px);
    hulls.emplace_back();
    for (int h : convex_hull_indices(means)) hulls.back().push_back(vertices[h]);
  }
  std::vector<Polygon> inner(hulls.size());
  for (auto _ : state)
    for (std::size_t i = 0; i < hulls.size(); ++i) {
      contract_region(hulls[i], ro, inner[i]);
      benchmark::DoNotOptimize(inner[i].data());
    }
}

}  // namespace

BENCHMARK(BM_FrameUnscented)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FrameLinear)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FrameUnscentedPerVertexScale)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FrameLinearPerVertexScale)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FrameProjectionOnlyUnscented)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FrameOuterOnly)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FrameInnerOnly)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FrameEightDegreesCubature)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FrameEightDegreesUnscented)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FrameMonteCarlo1000)->Unit(benchmark::kMillisecond);
// The figures are ratios within one run (the machine's speed cancels): after the
// usual table, the CPU time of each frame against the unscented frame.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  RatioReporter() : ConsoleReporter(OO_None) {}  // plain text, as when piped
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs)  // the plain runs, or the mean when repeated
      if (r.run_type == Run::RT_Iteration || r.aggregate_name == "mean")
        cpu_ms_[r.run_name.function_name] = r.GetAdjustedCPUTime();
  }
  void print_ratios() const {
    const auto unscented = cpu_ms_.find("BM_FrameUnscented");
    if (unscented == cpu_ms_.end()) return;
    std::printf("\nCPU time per frame as a ratio to BM_FrameUnscented (%.3f ms), same run:\n",
                unscented->second);
    for (const auto& [name, ms] : cpu_ms_)
      std::printf("  %-34s %8.3f\n", name.c_str(), ms / unscented->second);
  }

 private:
  std::map<std::string, double> cpu_ms_;
};

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  reporter.print_ratios();
  benchmark::Shutdown();
  return 0;
}
