// A consumer of the installed package: includes the umbrella header and uses
// one public type, so a missing header or a broken target fails to build.
#include <sphshell/sphshell.hpp>

#include <iostream>

int main() {
  try {
    sphshell::detail::require_positive("E", -1.0);
  } catch (const sphshell::Error& error) {
    std::cout << "downstream OK: " << error.what() << '\n';
    return 0;
  }
  return 1;
}
