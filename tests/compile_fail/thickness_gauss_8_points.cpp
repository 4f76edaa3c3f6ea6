// Must not compile: Gauss<N> is tabulated for N = 1..7.
#include <sphshell/thickness/gauss.hpp>

int main() { return sphshell::thickness::Gauss<8>::num_points; }
