#pragma once
// Every material law and the family contract.

#include <sphshell/material/cowper_symonds.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/material/flow_stress_return.hpp>
#include <sphshell/material/j2_plasticity.hpp>
#include <sphshell/material/johnson_cook.hpp>
#include <sphshell/material/lanes.hpp>
#include <sphshell/material/lemaitre_damage.hpp>
#include <sphshell/material/material.hpp>
#include <sphshell/material/return_map.hpp>
