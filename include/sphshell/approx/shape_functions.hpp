#pragma once
// Compressed storage of shape functions Φ_j and gradients ∇Φ_j at evaluation
// points (stress points or particles), built once and read in the force loop.

#include <cstddef>
#include <vector>

namespace sphshell::approx {

// Row r (one evaluation point) owns slots [row_begin[r], row_begin[r+1]).
// The first row_size[r] slots are the neighbours that take part (the visible
// ones), sorted by particle index; the remaining slots keep the neighbours that
// were hidden (Φ = ∇Φ = 0), so a row can be rebuilt in place later — when a
// crack cuts more pairs — from its full geometric neighbour set. Code that
// shrinks a row itself should therefore permute slots rather than overwrite
// neighbour indices.
// Φ_j and ∇Φ_j of one slot, kept side by side: the gather reads a row's slots
// in order, but the per-particle force sum visits the slots that refer to one
// particle — scattered over many rows — and needs all three of each, so one
// cache line then serves a slot instead of three.
struct ShapeValue {
  double phi = 0.0;      // Φ_j at the evaluation point
  double dphi_d1 = 0.0;  // ∇Φ_j in the evaluation point's tangent frame (e1, e2)
  double dphi_d2 = 0.0;

  friend bool operator==(const ShapeValue& a, const ShapeValue& b) {
    return a.phi == b.phi && a.dphi_d1 == b.dphi_d1 && a.dphi_d2 == b.dphi_d2;
  }
  friend bool operator!=(const ShapeValue& a, const ShapeValue& b) { return !(a == b); }
};

struct ShapeFunctions {
  std::vector<std::size_t> row_begin;  // size rows+1
  std::vector<int> row_size;           // used slots of row r (<= capacity)
  std::vector<int> neighbour;          // particle index per slot
  std::vector<ShapeValue> value;       // Φ_j, ∇Φ_j per slot
  std::vector<unsigned char> shepard;  // per row: 1 when the row fell back to the Shepard approximation

  std::size_t rows() const { return row_size.size(); }
  std::size_t capacity(std::size_t row) const { return row_begin[row + 1] - row_begin[row]; }
  std::size_t slots() const { return neighbour.size(); }

  // Heap bytes held by the storage (what a row costs in memory).
  std::size_t bytes() const {
    return row_begin.capacity() * sizeof(std::size_t) + row_size.capacity() * sizeof(int) +
           neighbour.capacity() * sizeof(int) + value.capacity() * sizeof(ShapeValue) +
           shepard.capacity() * sizeof(unsigned char);
  }
};

// The default visibility predicate: no pair is cut.
struct AlwaysVisible {
  bool operator()(std::size_t /*eval_index*/, std::size_t /*particle*/) const { return true; }
};

}  // namespace sphshell::approx
