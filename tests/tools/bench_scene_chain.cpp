// A scene whose frames form one long chain, f0 -> f1 -> ... -> fN, loaded the whole way
// (TOML text parsed, every transform added to a TransformGraph), the load's parts
// alone, the same chain loaded from a transform table (a CSV file the scene names), and
// a query end to end (T_f0_fN and its covariance through all N links).
// Linear cost means the same time per link at every length: after the usual table, each
// run's time per link is printed as a ratio to the 1,000-link run of the same benchmark
// (the machine's speed cancels).
// Run: taskset -c 0 build/tests/tools/bench_scene_chain
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <toml++/toml.h>

#include "covtrack/scene/scene.hpp"
#include "covtrack/scene/scene_graph.hpp"
#include "covtrack/scene/transform_table.hpp"

using namespace covtrack;

namespace {

// Each link moves 1 cm and turns 0.1 degree, with 0.1 mm and 0.1 mrad of noise. The
// camera a scene needs is named, not loaded (parse_scene only reads its path).
std::string chain_scene(int links) {
  std::string text = "[camera]\nframe = \"f0\"\ncalibration = \"camera.yml\"\n\n";
  text.reserve(static_cast<std::size_t>(links) * 180);
  for (int i = 0; i < links; ++i)
    fmt::format_to(std::back_inserter(text),
                   "[[transform]]\nparent = \"f{}\"\nchild = \"f{}\"\nposition_m = [0.01, 0, 0]\n"
                   "rotation_rpy_deg = [0, 0, 0.1]\nsigma_m = [1e-4, 1e-4, 1e-4]\n"
                   "sigma_rad = [1e-4, 1e-4, 1e-4]\n\n",
                   i, i + 1);
  return text;
}

// The same links as rows of a transform table, written to a real file that a scene names.
std::string chain_table_scene(int links, const std::filesystem::path& dir) {
  std::string rows{scene::kTransformTableHeader};
  rows += '\n';
  for (int i = 0; i < links; ++i)
    fmt::format_to(std::back_inserter(rows), "f{},f{},0.01,0,0,0,0,0.1,1e-4,1e-4,1e-4,1e-4,1e-4,1e-4\n", i, i + 1);
  const std::string name = fmt::format("chain_{}.csv", links);
  std::ofstream(dir / name, std::ios::binary) << rows;
  return fmt::format("transform_tables = [\"{}\"]\n[camera]\nframe = \"f0\"\ncalibration = \"camera.yml\"\n", name);
}

scene::Scene parse(const std::string& text, const std::string& base_dir = ".") {
  auto scene = scene::parse_scene(text, "chain.toml", base_dir);
  if (!scene) throw std::runtime_error(scene.error().message);
  return std::move(*scene);
}

void add(const scene::Scene& scene, client::TransformGraph& graph) {
  if (auto added = scene::add_scene_transforms(scene, graph, std::nullopt); !added)
    throw std::runtime_error(added.error().message);
}

// The whole load: text to a graph ready for queries.
void BM_LoadChain(benchmark::State& state) {
  const int links = static_cast<int>(state.range(0));
  const std::string text = chain_scene(links);
  for (auto _ : state) {
    client::TransformGraph graph;
    add(parse(text), graph);
    benchmark::DoNotOptimize(&graph);
  }
  state.counters["links"] = links;
}

// The whole load from a transform table: the scene, the file read and parsed, the graph.
void BM_LoadChainTable(benchmark::State& state) {
  const int links = static_cast<int>(state.range(0));
  const auto dir = std::filesystem::temp_directory_path() / fmt::format("bench_scene_chain_{}", getpid());
  std::filesystem::create_directories(dir);
  const std::string text = chain_table_scene(links, dir);
  for (auto _ : state) {
    client::TransformGraph graph;
    add(parse(text, dir.string()), graph);
    benchmark::DoNotOptimize(&graph);
  }
  std::filesystem::remove_all(dir);
  state.counters["links"] = links;
}

// Its two parts: the scene's transforms added to a graph (client/ and tools/scene) ...
void BM_GraphChain(benchmark::State& state) {
  const int links = static_cast<int>(state.range(0));
  const scene::Scene scene = parse(chain_scene(links));
  for (auto _ : state) {
    client::TransformGraph graph;
    add(scene, graph);
    benchmark::DoNotOptimize(&graph);
  }
  state.counters["links"] = links;
}

// ... and the text parsed and checked into a Scene, of which toml++'s parse is most.
void BM_ParseChain(benchmark::State& state) {
  const int links = static_cast<int>(state.range(0));
  const std::string text = chain_scene(links);
  for (auto _ : state) benchmark::DoNotOptimize(parse(text));
  state.counters["links"] = links;
}

void BM_TomlChain(benchmark::State& state) {
  const int links = static_cast<int>(state.range(0));
  const std::string text = chain_scene(links);
  for (auto _ : state) {
    toml::table table = toml::parse(text);
    benchmark::DoNotOptimize(&table);
  }
  state.counters["links"] = links;
}

// T_f0_fN through every link, with its covariance.
void BM_QueryChain(benchmark::State& state) {
  const int links = static_cast<int>(state.range(0));
  client::TransformGraph graph;
  add(parse(chain_scene(links)), graph);
  const std::string leaf = fmt::format("f{}", links);
  for (auto _ : state) {
    auto pose = graph.query("f0", leaf, 0);
    if (!pose) throw std::runtime_error(pose.error().message);
    benchmark::DoNotOptimize(pose->covariance.data());
  }
  state.counters["links"] = links;
}

}  // namespace

#define CHAIN_LENGTHS ->Arg(1'000)->Arg(10'000)->Arg(100'000)->Unit(benchmark::kMillisecond)
BENCHMARK(BM_LoadChain) CHAIN_LENGTHS;
BENCHMARK(BM_LoadChainTable) CHAIN_LENGTHS;
BENCHMARK(BM_GraphChain) CHAIN_LENGTHS;
BENCHMARK(BM_ParseChain) CHAIN_LENGTHS;
BENCHMARK(BM_TomlChain) CHAIN_LENGTHS;
BENCHMARK(BM_QueryChain) CHAIN_LENGTHS;

// CPU time per link of each run against the 1,000-link run of the same benchmark.
class PerLinkReporter : public benchmark::ConsoleReporter {
 public:
  PerLinkReporter() : ConsoleReporter(OO_None) {}  // plain text, as when piped
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs)
      if (r.run_type == Run::RT_Iteration || r.aggregate_name == "mean")
        per_link_ms_[r.run_name.function_name][static_cast<int>(r.counters.at("links"))] =
            r.GetAdjustedCPUTime() / r.counters.at("links");
  }
  void print_ratios() const {
    std::printf("\nCPU time per link as a ratio to 1,000 links, same run (1 = linear):\n");
    for (const auto& [name, by_links] : per_link_ms_) {
      const auto base = by_links.find(1'000);
      if (base == by_links.end()) continue;
      for (const auto& [links, ms] : by_links)
        std::printf("  %-14s %7d links: %9.3f us/link, ratio %6.2f\n", name.c_str(), links, ms * 1e3,
                    ms / base->second);
    }
  }

 private:
  std::map<std::string, std::map<int, double>> per_link_ms_;
};

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  PerLinkReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  reporter.print_ratios();
  benchmark::Shutdown();
  return 0;
}
