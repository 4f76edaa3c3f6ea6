#pragma once
// Segment-crossing predicate of the visibility criterion (docs/method.md §6, item 4):
// a particle pair (a, b) is cut by a crack segment (c1, c2) when
//   s(a; c1,c2) · s(b; c1,c2) < 0   and   s(c1; a,b) · s(c2; a,b) <= 0,
// with s(P; A,B) the signed side of P relative to the line AB. Only the signs
// matter, so the orientation test returns an exact sign: a wrong sign on a
// nearly collinear pair would let particles interact through a crack (or cut a
// pair that should see its neighbour), depending on round-off.
// The exact fallback relies on IEEE round-to-nearest semantics: -ffast-math
// (or -fassociative-math) lets the compiler cancel its error terms and voids
// the guarantee. Fused multiply-add contraction is harmless.

#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <sstream>

namespace sphshell::crack {

namespace detail {

// x + y = sum + error exactly (Knuth's branch-free two-sum); additions only, so
// floating-point contraction cannot alter it.
inline void two_sum(double x, double y, double& sum, double& error) {
  sum = x + y;
  const double y_virtual = sum - x;
  const double x_virtual = sum - y_virtual;
  error = (x - x_virtual) + (y - y_virtual);
}

// x · y = product + error exactly, as long as the product neither overflows nor
// underflows. std::fma rounds once, so the error term is exact even on targets
// where the compiler would contract a Dekker split into a fused operation.
inline void two_product(double x, double y, double& product, double& error) {
  product = x * y;
  error = std::fma(x, y, -product);
}

// Exact sign of the orientation determinant, evaluated as an expansion
// (Shewchuk 1997): the determinant is rewritten as six products of input
// coordinates, each split exactly into two doubles, and the twelve terms are
// accumulated into a non-overlapping expansion whose largest component carries
// the sign of the exact sum. Slow (a few hundred flops) but only reached when the
// floating-point filter in orientation() cannot decide.
inline double orientation_exact(const Vector2& a, const Vector2& b, const Vector2& p) {
  const double factors[6][2] = {{b.x(), p.y()},  {-b.x(), a.y()}, {-a.x(), p.y()},
                                {-b.y(), p.x()}, {a.x(), b.y()},  {a.y(), p.x()}};
  // Components in increasing magnitude, zeros dropped; at most 12 survive.
  std::array<double, 12> expansion{};
  std::size_t length = 0;
  auto grow = [&](double term) {
    double carry = term;
    std::size_t kept = 0;
    for (std::size_t i = 0; i < length; ++i) {
      double sum = 0.0;
      double error = 0.0;
      two_sum(carry, expansion[i], sum, error);
      carry = sum;
      if (error != 0.0) expansion[kept++] = error;
    }
    if (carry != 0.0) expansion[kept++] = carry;
    length = kept;
  };
  for (const auto& factor : factors) {
    double product = 0.0;
    double error = 0.0;
    two_product(factor[0], factor[1], product, error);
    grow(error);
    grow(product);
  }
  if (length == 0) return 0.0;
  const double largest = expansion[length - 1];
  double estimate = 0.0;
  for (std::size_t i = 0; i < length; ++i) estimate += expansion[i];
  // The rounded estimate is the better magnitude; the largest component is the
  // authority on the sign should rounding ever disagree.
  return (estimate > 0.0) == (largest > 0.0) && estimate != 0.0 ? estimate : largest;
}

[[noreturn]] inline void reject_non_finite(const Vector2& a, const Vector2& b,
                                           const Vector2& p) {
  std::ostringstream message;
  message.precision(17);
  message << "sphshell: orientation test needs finite coordinates, got a = (" << a.x() << ", "
          << a.y() << "), b = (" << b.x() << ", " << b.y() << "), p = (" << p.x() << ", " << p.y()
          << ")";
  throw Error(message.str());
}

}  // namespace detail

// Twice the signed area of the triangle (a, b, p): > 0 when p lies to the left
// of the directed line a→b (a, b, p counter-clockwise), < 0 to the right, 0 when
// collinear. The sign is exact for finite inputs whose coordinate products
// neither overflow nor underflow (magnitudes roughly within 1e-150 .. 1e150,
// or zero); the magnitude is approximate. Non-finite input raises Error.
inline double orientation(const Vector2& a, const Vector2& b, const Vector2& p) {
  const double left = (a.x() - p.x()) * (b.y() - p.y());
  const double right = (a.y() - p.y()) * (b.x() - p.x());
  const double determinant = left - right;
  // Shewchuk's stage-A bound is (3 + 16ε)ε·(|left| + |right|); 4ε is a little
  // looser, which keeps the filter valid if the compiler fuses the final
  // multiply-subtract (one rounding fewer, never more error).
  constexpr double epsilon = std::numeric_limits<double>::epsilon() / 2.0;
  const double bound = 4.0 * epsilon * (std::abs(left) + std::abs(right));
  // bound is finite exactly when every intermediate is, so NaN or infinity in
  // the input falls through to the checked slow path. Exact zeros (left = right
  // = 0, common on particle lattices) pass with bound = 0 and stay fast.
  if (bound <= std::numeric_limits<double>::max() && std::abs(determinant) >= bound)
    return determinant;
  if (!(std::isfinite(a.x()) && std::isfinite(a.y()) && std::isfinite(b.x()) &&
        std::isfinite(b.y()) && std::isfinite(p.x()) && std::isfinite(p.y())))
    detail::reject_non_finite(a, b, p);
  return detail::orientation_exact(a, b, p);
}

// -1, 0 or +1: the exact side of p relative to the line a→b.
inline int side_of_line(const Vector2& a, const Vector2& b, const Vector2& p) {
  const double value = orientation(a, b, p);
  return (value > 0.0) - (value < 0.0);
}

// True when the crack segment blocks the interaction between particles a and b
// (the pair is "invalid"; otherwise it is "effective"):
//   - the pair must straddle the crack's line strictly: a particle lying on the
//     crack's line (or its extension) is never cut off by it;
//   - the crack must reach the pair's line: both crack ends strictly on one side
//     leave the pair visible, a crack end touching the pair's connection cuts it.
// Degenerate inputs fall out of the rule without special cases: a zero-length
// crack (c1 = c2) has every point "on" its line and never cuts; a zero-length
// pair never straddles anything; collinear pair and crack never cut.
inline bool pair_is_cut(const Vector2& a, const Vector2& b, const Vector2& crack_start,
                        const Vector2& crack_end) {
  const int side_a = side_of_line(crack_start, crack_end, a);
  const int side_b = side_of_line(crack_start, crack_end, b);
  if (side_a * side_b >= 0) return false;
  const int side_start = side_of_line(a, b, crack_start);
  const int side_end = side_of_line(a, b, crack_end);
  return side_start * side_end <= 0;
}

// Coordinates of point in the tangent plane of frame about origin, i.e. the
// orthogonal projection of (point - origin) onto (e1, e2).
inline Vector2 project_onto_tangent_plane(const Vector3& point, const Vector3& origin,
                                          const TangentFrame& frame) {
  const Vector3 offset = point - origin;
  return {offset.dot(frame.e1), offset.dot(frame.e2)};
}

// pair_is_cut for points on a curved shell: the pair and the crack segment are
// projected onto the tangent plane at origin (usually the point being
// approximated, whose support domain is small next to the curvature radius)
// and tested there. The sign is exact for the projected coordinates; the
// projection itself rounds. For a plate in the xy-plane with frame
// tangent_frame(z) and origin zero the projection is exact.
inline bool pair_is_cut_in_tangent_plane(const Vector3& a, const Vector3& b,
                                         const Vector3& crack_start, const Vector3& crack_end,
                                         const TangentFrame& frame, const Vector3& origin) {
  return pair_is_cut(project_onto_tangent_plane(a, origin, frame),
                     project_onto_tangent_plane(b, origin, frame),
                     project_onto_tangent_plane(crack_start, origin, frame),
                     project_onto_tangent_plane(crack_end, origin, frame));
}

}  // namespace sphshell::crack
