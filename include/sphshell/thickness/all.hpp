#pragma once
// Every thickness rule and Section<Rule, Law>.

#include <sphshell/thickness/gauss.hpp>
#include <sphshell/thickness/global.hpp>
#include <sphshell/thickness/section.hpp>
#include <sphshell/thickness/section_group.hpp>
#include <sphshell/thickness/simpson.hpp>
#include <sphshell/thickness/thickness.hpp>
