// The cell list against Debian's nanoflann k-d tree: build over the particles
// of an n × n plate plus one radius query (2 spacings) per stress point — the
// work of a shape-function build. nanoflann is only compared when installed.
#include <sphshell/approx/neighbour_search.hpp>

#include <benchmark/benchmark.h>

#include <vector>

#if __has_include(<nanoflann.hpp>)
#include <nanoflann.hpp>
#define SPHSHELL_HAVE_NANOFLANN 1
#endif

using namespace sphshell;

namespace {

struct Plate {
  std::vector<Vector3> particles;
  std::vector<Vector3> stress_points;
  double radius = 0.0;
};

Plate make_plate(int n) {
  Plate plate;
  const double spacing = 1.0 / (n - 1);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) plate.particles.emplace_back(i * spacing, j * spacing, 0.0);
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i)
      plate.stress_points.emplace_back((i + 0.5) * spacing, (j + 0.5) * spacing, 0.0);
  plate.radius = 2.0 * spacing;
  return plate;
}

void set_counters(benchmark::State& state, const Plate& plate, std::size_t found) {
  state.counters["time_per_point"] = benchmark::Counter(
      double(plate.stress_points.size()),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["neighbours_per_point"] = double(found) / double(plate.stress_points.size());
}

void cell_list(benchmark::State& state) {
  const Plate plate = make_plate(int(state.range(0)));
  std::size_t found = 0;
  for (auto _ : state) {
    const approx::CellList cells(plate.particles, plate.radius);
    found = 0;
    for (const Vector3& x : plate.stress_points)
      cells.for_each_within(x, plate.radius, [&found](int, double) { ++found; });
    benchmark::DoNotOptimize(found);
  }
  set_counters(state, plate, found);
}
BENCHMARK(cell_list)->Arg(51)->Arg(201)->Arg(801)->Unit(benchmark::kMillisecond);

#ifdef SPHSHELL_HAVE_NANOFLANN
struct PointCloud {
  const std::vector<Vector3>* points;
  std::size_t kdtree_get_point_count() const { return points->size(); }
  double kdtree_get_pt(std::size_t i, std::size_t dim) const { return (*points)[i][int(dim)]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const { return false; }
};
using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointCloud>,
                                                   PointCloud, 3>;

void nanoflann_kd_tree(benchmark::State& state) {
  const Plate plate = make_plate(int(state.range(0)));
  const PointCloud cloud{&plate.particles};
  std::size_t found = 0;
  std::vector<std::pair<std::size_t, double>> matches;
  matches.reserve(64);
  for (auto _ : state) {
    KdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    found = 0;
    for (const Vector3& x : plate.stress_points) {
      nanoflann::RadiusResultSet<double, std::size_t> result(plate.radius * plate.radius, matches);
      tree.radiusSearchCustomCallback(x.data(), result, nanoflann::SearchParams(32, 0.0, false));
      found += matches.size();
    }
    benchmark::DoNotOptimize(found);
  }
  set_counters(state, plate, found);
}
BENCHMARK(nanoflann_kd_tree)->Arg(51)->Arg(201)->Arg(801)->Unit(benchmark::kMillisecond);
#endif

}  // namespace

BENCHMARK_MAIN();
