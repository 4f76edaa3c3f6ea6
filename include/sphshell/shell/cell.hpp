#pragma once
// The cells of a shell model: quadrilaterals and triangles over the particles,
// each with a stress point at its centre (docs/method.md §1).

#include <array>
#include <cstddef>
#include <vector>

namespace sphshell {

using ParticleSet = std::vector<int>;

// Four particle indices of a quadrilateral cell, counter-clockwise seen from the
// side the normals point to; a stress point sits at each cell's centre.
using Quad = std::array<int, 4>;

// Corner particle indices of a triangular (3) or quadrilateral (4) cell, in
// counter-clockwise order seen from the side the normals point to; the cell's
// stress point sits at its centre.
class Cell {
 public:
  Cell(int a, int b, int c) : corners_{a, b, c, -1}, size_(3) {}
  Cell(int a, int b, int c, int d) : corners_{a, b, c, d}, size_(4) {}
  explicit Cell(const Quad& quad) : corners_(quad), size_(4) {}
  std::size_t size() const { return size_; }
  bool is_triangle() const { return size_ == 3; }
  int operator[](std::size_t k) const { return corners_[k]; }
  const int* begin() const { return corners_.data(); }
  const int* end() const { return corners_.data() + size_; }

 private:
  std::array<int, 4> corners_;
  std::size_t size_;
};

// Two cells that share an edge and run along it in the same direction (their
// normals flip across it), a third cell on an edge (a junction, which one
// director per particle cannot represent), or two cells whose orientations
// no turning of cells can make agree (a one-sided surface, a Möbius strip).
struct CellEdgeProblem {
  enum class Kind { flipped, junction, unorientable };
  Kind kind;
  int first_cell;
  int second_cell;
  int edge_start;  // particle indices of the shared edge
  int edge_end;
};

}  // namespace sphshell
