// Placeholder until the solver lands (issue 4): prints the library version.
#include <sphshell/sphshell.hpp>

#include <iostream>

int main() {
  std::cout << "sphshell square_plate: the solver is not built yet\n";
  return 0;
}
