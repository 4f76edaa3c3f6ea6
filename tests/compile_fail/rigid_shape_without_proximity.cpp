// A rigid shape must say where a point is: one without proximity() is refused
// by the contact family's contract (contact/contact.hpp).
#include <sphshell/contact/rigid_body.hpp>

struct Blob {
  static constexpr bool bounded = true;
};

int main() {
  sphshell::contact::RigidBody<Blob, sphshell::contact::Fixed> body(Blob{}, sphshell::contact::Fixed{});
  return body.position().norm() > 0.0;
}
