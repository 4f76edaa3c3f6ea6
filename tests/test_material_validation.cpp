#include <sphshell/core/error.hpp>
#include <sphshell/material/all.hpp>

#include <catch2/catch.hpp>

#include <limits>

using namespace sphshell;
using namespace sphshell::material;

namespace {
const double nan_value = std::numeric_limits<double>::quiet_NaN();
const LemaitreDamage::Parameters good{210e9, 0.3, 235e6, 1e9, 0.02, 0.37, 0.24};
}  // namespace

TEST_CASE("Valid parameters construct every law", "[material][validation]") {
  CHECK_NOTHROW(Elastic({210e9, 0.3}));
  CHECK_NOTHROW(J2Plasticity({210e9, -0.5, 235e6, 0.0}));
  CHECK_NOTHROW(LemaitreDamage(good));
  LemaitreDamage::Parameters edge = good;
  edge.eps_s = 0.0;
  edge.Dc = 1.0;
  CHECK_NOTHROW(LemaitreDamage(edge));
}

TEST_CASE("Invalid elastic constants name the parameter and its value", "[material][validation]") {
  CHECK_THROWS_WITH(Elastic({-1.0, 0.3}),
                    Catch::Contains("parameter E =") && Catch::Contains("-1"));
  CHECK_THROWS_WITH(Elastic({0.0, 0.3}), Catch::Contains("parameter E ="));
  CHECK_THROWS_WITH(Elastic({nan_value, 0.3}),
                    Catch::Contains("parameter E =") && Catch::Contains("nan"));
  CHECK_THROWS_WITH(Elastic({210e9, 0.5}),
                    Catch::Contains("parameter nu =") && Catch::Contains("0.5"));
  CHECK_THROWS_WITH(Elastic({210e9, -1.0}),
                    Catch::Contains("parameter nu =") && Catch::Contains("-1"));
  CHECK_THROWS_WITH(Elastic({210e9, nan_value}), Catch::Contains("parameter nu ="));
  CHECK_THROWS_AS(J2Plasticity({210e9, 0.7, 235e6, 0.0}), Error);
  CHECK_THROWS_WITH(J2Plasticity({-5.0, 0.3, 235e6, 0.0}), Catch::Contains("parameter E ="));
}

TEST_CASE("Invalid plastic parameters name the parameter and its value", "[material][validation]") {
  CHECK_THROWS_WITH(J2Plasticity({210e9, 0.3, 0.0, 0.0}),
                    Catch::Contains("parameter sigma_y0 =") && Catch::Contains("0"));
  CHECK_THROWS_WITH(J2Plasticity({210e9, 0.3, -235e6, 0.0}),
                    Catch::Contains("parameter sigma_y0 =") && Catch::Contains("-235000000"));
  CHECK_THROWS_WITH(J2Plasticity({210e9, 0.3, nan_value, 0.0}),
                    Catch::Contains("parameter sigma_y0 ="));
  CHECK_THROWS_WITH(J2Plasticity({210e9, 0.3, 235e6, -1e9}),
                    Catch::Contains("parameter Ep =") && Catch::Contains("-1000000000"));
  CHECK_THROWS_WITH(J2Plasticity({210e9, 0.3, 235e6, nan_value}),
                    Catch::Contains("parameter Ep ="));
  CHECK_THROWS_WITH(J2Plasticity({210e9, 0.3, 235e6, std::numeric_limits<double>::infinity()}),
                    Catch::Contains("parameter Ep ="));
}

TEST_CASE("Invalid damage parameters name the parameter and its value", "[material][validation]") {
  auto with = [](auto change) {
    LemaitreDamage::Parameters p = good;
    change(p);
    return p;
  };
  CHECK_THROWS_WITH(LemaitreDamage(with([](auto& p) { p.eps_s = -0.01; })),
                    Catch::Contains("parameter eps_s =") && Catch::Contains("-0.01"));
  CHECK_THROWS_WITH(LemaitreDamage(with([](auto& p) { p.eps_s = nan_value; })),
                    Catch::Contains("parameter eps_s ="));
  CHECK_THROWS_WITH(LemaitreDamage(with([](auto& p) { p.eps_c = 0.02; })),
                    Catch::Contains("parameter eps_c =") && Catch::Contains("0.02"));
  CHECK_THROWS_WITH(LemaitreDamage(with([](auto& p) { p.eps_c = 0.01; })),
                    Catch::Contains("parameter eps_c =") && Catch::Contains("0.01"));
  CHECK_THROWS_WITH(LemaitreDamage(with([](auto& p) { p.eps_c = nan_value; })),
                    Catch::Contains("parameter eps_c ="));
  CHECK_THROWS_WITH(
      LemaitreDamage(with([](auto& p) { p.eps_c = std::numeric_limits<double>::infinity(); })),
      Catch::Contains("parameter eps_c ="));
  CHECK_THROWS_WITH(LemaitreDamage(with([](auto& p) { p.Dc = 0.0; })),
                    Catch::Contains("parameter Dc =") && Catch::Contains("0"));
  CHECK_THROWS_WITH(LemaitreDamage(with([](auto& p) { p.Dc = 1.2; })),
                    Catch::Contains("parameter Dc =") && Catch::Contains("1.2"));
  CHECK_THROWS_WITH(LemaitreDamage(with([](auto& p) { p.Dc = nan_value; })),
                    Catch::Contains("parameter Dc ="));
  CHECK_THROWS_WITH(LemaitreDamage(with([](auto& p) { p.sigma_y0 = -1.0; })),
                    Catch::Contains("parameter sigma_y0 ="));
  CHECK_THROWS_WITH(LemaitreDamage(with([](auto& p) { p.Ep = -2.0; })),
                    Catch::Contains("parameter Ep ="));
  CHECK_THROWS_WITH(LemaitreDamage(with([](auto& p) { p.nu = 0.5; })),
                    Catch::Contains("parameter nu ="));
  CHECK_THROWS_WITH(LemaitreDamage(with([](auto& p) { p.E = nan_value; })),
                    Catch::Contains("parameter E ="));
  CHECK_THROWS_AS(LemaitreDamage(with([](auto& p) { p.Dc = -0.1; })), Error);
}
