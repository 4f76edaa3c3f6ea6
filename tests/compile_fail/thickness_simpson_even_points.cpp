// Must not compile: composite Simpson needs an odd number of points.
#include <sphshell/thickness/simpson.hpp>

int main() { return sphshell::thickness::Simpson<4>::num_points; }
