#include <sphshell/approx/neighbour_search.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <utility>
#include <vector>

using namespace sphshell;
using approx::CellList;

namespace {

std::vector<int> brute_force(const std::vector<Vector3>& points, const Vector3& x, double radius) {
  std::vector<int> found;
  for (std::size_t i = 0; i < points.size(); ++i)
    if ((points[i] - x).squaredNorm() < radius * radius) found.push_back(int(i));
  return found;
}

std::vector<int> cell_list_query(const CellList& cells, const Vector3& x, double radius) {
  std::vector<int> found;
  cells.for_each_within(x, radius, [&](int j, double) { found.push_back(j); });
  std::sort(found.begin(), found.end());
  return found;
}

}  // namespace

TEST_CASE("Cell list finds exactly the points a brute-force search finds", "[approx][neighbours]") {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> angle(0.0, 6.283185307179586);
  std::uniform_real_distribution<double> height(0.0, 0.5);
  std::uniform_real_distribution<double> cloud(-0.3, 0.3);
  std::vector<Vector3> points;
  // A cylinder of radius 0.1 (a curved shell) plus a cloud around it.
  for (int i = 0; i < 2000; ++i) {
    const double t = angle(random);
    points.emplace_back(0.1 * std::cos(t), 0.1 * std::sin(t), height(random));
  }
  for (int i = 0; i < 500; ++i) points.emplace_back(cloud(random), cloud(random), cloud(random));
  const double radius = 0.03;
  const CellList cells(points, radius);
  CHECK_FALSE(cells.dense());  // a dense grid would hold 3.5 cells per point
  CHECK(cells.size() == points.size());
  std::vector<Vector3> queries(points.begin(), points.begin() + 300);
  for (int i = 0; i < 200; ++i) queries.emplace_back(cloud(random), cloud(random), 2 * cloud(random));
  queries.emplace_back(10.0, -10.0, 1e6);  // far outside the grid
  std::size_t total = 0;
  for (const Vector3& q : queries) {
    const auto expected = brute_force(points, q, radius);
    total += expected.size();
    CHECK(cell_list_query(cells, q, radius) == expected);
    CHECK(cell_list_query(cells, q, 0.5 * radius) == brute_force(points, q, 0.5 * radius));
  }
  CHECK(total > queries.size());  // the comparison is not vacuous
  // A radius above the cells' own visits more layers of cells (a row whose
  // local support is wider than the median's): still exactly the brute-force set.
  for (std::size_t k = 0; k < queries.size(); k += 7) {
    CHECK(cell_list_query(cells, queries[k], 2 * radius) == brute_force(points, queries[k], 2 * radius));
    CHECK(cell_list_query(cells, queries[k], 3.5 * radius) == brute_force(points, queries[k], 3.5 * radius));
  }
  CHECK_THROWS_AS(cells.for_each_within(Vector3::Zero(), -radius, [](int, double) {}), Error);
  CHECK_THROWS_AS(cells.for_each_within(Vector3::Zero(), std::nan(""), [](int, double) {}), Error);
}

TEST_CASE("Cell list over a flat jittered sheet uses dense cells and finds the same points",
          "[approx][neighbours]") {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> jitter(-0.3e-2, 0.3e-2);
  std::vector<Vector3> points;
  for (int j = 0; j < 60; ++j)
    for (int i = 0; i < 60; ++i)
      points.emplace_back(i * 1e-2 + jitter(random), j * 1e-2 + jitter(random), 1e-4 * jitter(random));
  const double radius = 2e-2;
  const CellList cells(points, radius);
  CHECK(cells.dense());
  std::uniform_real_distribution<double> anywhere(-0.05, 0.65);
  std::size_t total = 0;
  for (int q = 0; q < 600; ++q) {
    const Vector3 x = q < 300 ? points[std::size_t(q * 11)]
                              : Vector3(anywhere(random), anywhere(random), 0.3 * jitter(random));
    const auto expected = brute_force(points, x, radius);
    total += expected.size();
    CHECK(cell_list_query(cells, x, radius) == expected);
  }
  CHECK(total > 3000);
}

TEST_CASE("Cell list by slot: the same points in the same order, each slot's index and coordinates",
          "[approx][neighbours]") {
  // A jittered sheet (dense cells) and a cylinder's surface (hashed cells):
  // for_each_slot_within visits what for_each_within visits, in its order,
  // and the slots are a permutation of the points holding their coordinates.
  std::mt19937 random(11);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2), angle(0.0, 6.283185307179586), height(0.0, 0.5);
  std::vector<Vector3> sheet, cylinder;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j) sheet.emplace_back(i + jitter(random), j + jitter(random), 0.1 * jitter(random));
  for (int i = 0; i < 2000; ++i) {
    const double t = angle(random);
    cylinder.emplace_back(0.1 * std::cos(t), 0.1 * std::sin(t), height(random));
  }
  for (const auto& [points, radius] : {std::pair{sheet, 2.5}, std::pair{cylinder, 0.03}}) {
    const CellList cells(points, radius);
    std::vector<int> seen(points.size(), 0);
    for (std::size_t slot = 0; slot < cells.size(); ++slot) {
      const auto i = static_cast<std::size_t>(cells.point_at(slot));
      REQUIRE(i < points.size());
      ++seen[i];
      CHECK(cells.position_at(slot) == points[i]);
    }
    CHECK(std::count(seen.begin(), seen.end(), 1) == static_cast<std::ptrdiff_t>(points.size()));
    std::size_t visits = 0;
    for (std::size_t q = 0; q < points.size(); q += 13) {
      std::vector<std::pair<int, double>> by_index, by_slot;
      cells.for_each_within(points[q], radius, [&](int j, double d) { by_index.emplace_back(j, d); });
      cells.for_each_slot_within(points[q], radius, [&](std::size_t slot, double d) {
        by_slot.emplace_back(cells.point_at(slot), d);
        CHECK(d == (cells.position_at(slot) - points[q]).squaredNorm());
      });
      CHECK(by_slot == by_index);
      visits += by_slot.size();
    }
    CHECK(visits > 2 * points.size() / 13);  // not vacuous: several neighbours per query
  }
}

TEST_CASE("Cell list rejects invalid input and finds coincident points", "[approx][neighbours]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<Vector3> points{{0, 0, 0}, {1, 0, 0}, {0, nan, 0}};
  CHECK_THROWS_WITH(CellList(points, 0.5), Catch::Contains("point 2"));
  points[2] = {0, 1, 0};
  CHECK_THROWS_AS(CellList(points, 0.0), Error);
  CHECK_THROWS_AS(CellList(points, nan), Error);
  CHECK_NOTHROW(CellList(points, 0.5).require_no_coincident_points(1e-9, "particles"));
  points.push_back({1, 0, 0});
  CHECK_THROWS_WITH(CellList(points, 0.5).require_no_coincident_points(1e-9, "particles"),
                    Catch::Contains("particles 1 and 3"));
  // Nearly coincident points on both sides of a cell face are found as well.
  std::vector<Vector3> straddling{{0, 0, 0}, {0.5 - 1e-12, 0.2, 0}, {0.5 + 1e-12, 0.2, 0}, {1, 1, 1}};
  CHECK_THROWS_WITH(CellList(straddling, 0.5).require_no_coincident_points(1e-9, "points"),
                    Catch::Contains("points 1 and 2"));
  const CellList empty(std::vector<Vector3>{}, 1.0);
  CHECK(cell_list_query(empty, Vector3::Zero(), 1.0).empty());
}
