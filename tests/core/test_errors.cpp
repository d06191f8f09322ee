#include "core/errors.h"
#include "core/vec3.h"

#include <catch2/catch.hpp>

using namespace dipper;

TEST_CASE("range checks name the value, the key and the source", "[core][unit]")
{
    REQUIRE_THROWS_WITH(require_positive(-0.02, "radius_m", "spawn 17"),
                        Catch::Contains("radius_m") && Catch::Contains("-0.02") && Catch::Contains("spawn 17"));
    REQUIRE_THROWS_AS(require_positive(std::nan(""), "radius_m", "x"), InputError);
    REQUIRE_THROWS_WITH(require_in_range(1.5, 0.0, 1.0, "D_n", "table"), Catch::Contains("[0, 1]"));
    REQUIRE_NOTHROW(require_non_negative(0.0, "friction", "x"));
}

TEST_CASE("rotation about an axis is orthonormal and turns as the right-hand rule says", "[core][unit]")
{
    const Mat3 r = rotation_about_axis({0.0, 0.0, 1.0}, M_PI / 2.0);
    const Vec3 x = r * Vec3{1.0, 0.0, 0.0};
    CHECK(x.x == Approx(0.0).margin(1e-15));
    CHECK(x.y == Approx(1.0).epsilon(1e-15));
    const Mat3 i = r * r.transposed();
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) CHECK(i.m[a][b] == Approx(a == b ? 1.0 : 0.0).margin(1e-15));
}
