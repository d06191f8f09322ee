// Generated machine geometry: the dipper's struck volume and rake angle, its wear-bar variants, plates whose
// surfaces are closed and outward, the feeder, truck body and ground, and bad parameters.
#include "core/errors.h"
#include "meshes/machine_geometry.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace dipper;
using namespace dipper::meshes;

namespace {

/// Every plate's own surface encloses exactly its volume (face area x thickness): the faces are closed and
/// all point outwards.
void check_plates_closed(const MachinePart& part)
{
    for (std::size_t k = 0; k < part.plates.size(); ++k) {
        CAPTURE(part.name, k);
        const Plate& p = part.plates[k];
        const auto& c = p.corners_m;
        const double area = 0.5 * norm(cross(c[2] - c[0], c[1] - c[0])) + 0.5 * norm(cross(c[3] - c[0], c[2] - c[0]));
        const MachinePart single = make_part("one", {p}, 0.2);
        CHECK(enclosed_volume_m3(single.surface) == Approx(area * p.thickness_m).epsilon(1e-9));
    }
}

double max_edge(const TriangleMesh& m)
{
    double e = 0.0;
    for (const auto& t : m.triangles())
        for (int k = 0; k < 3; ++k)
            e = std::max(e, norm(m.vertices_m()[t[static_cast<std::size_t>(k)]] - m.vertices_m()[t[static_cast<std::size_t>((k + 1) % 3)]]));
    return e;
}

}  // namespace

TEST_CASE("the dipper: 4 x 4 x 3 m, struck volume 42 m^3 from its geometry, rake angle as configured", "[meshes][machine][unit]")
{
    const Dipper d = make_dipper({});
    // struck volume of the inside closed by the door and the strike plane: W H (L_bottom + L_top) / 2
    CHECK(d.struck_volume_m3 == Approx(4.0 * 3.0 * (4.0 + 3.0) / 2.0).epsilon(1e-12));
    CHECK(d.struck_volume_m3 == Approx(42.0).epsilon(1e-12));
    const Vec3 lo = d.body.surface.bounds_min_m(), hi = d.body.surface.bounds_max_m();
    CHECK(hi.y - lo.y == Approx(4.2));             // inside width 4 m plus two 0.1 m side plates
    CHECK(hi.z - lo.z == Approx(3.0 + 0.1 + 0.2));  // inside height, top plate, lip
    CHECK(hi.x - lo.x == Approx(4.5));             // bottom to the lip, and the teeth
    for (const double rake : {57.8, 59.8, 61.8, 63.8, 65.8}) {
        DipperParameters p;
        p.rake_angle_deg = rake;
        p.element_size_m = 0.3;
        const Dipper r = make_dipper(p);
        CHECK(r.measured_rake_angle_deg() == Approx(rake).epsilon(1e-12));
        CHECK(norm(r.handle_direction) == Approx(1.0));
        CHECK(r.handle_direction.z > 0.0);  // the handle leaves through the top
    }
    check_plates_closed(d.body);
    check_plates_closed(d.door);
    CHECK(max_edge(d.body.surface) <= 0.075 * std::sqrt(2.0) + 1e-9);
    CHECK(d.body.triangle_plate.size() == d.body.surface.triangle_count());
    // the door closes the rear: its face lies in the plane x = 0 when placed at the hinge
    for (const Vec3& v : d.door.surface.vertices_m()) CHECK(v.x <= 1e-12);
    CHECK(d.door_hinge_m.z == Approx(3.0));
    CHECK(d.bail_pins_m[0].y < -2.0);
    CHECK(d.bail_pins_m[1].y > 2.0);
}

TEST_CASE("wear-bar variants: bars on the bottom at 90 and 45 degrees to the flow", "[meshes][machine][unit]")
{
    DipperParameters p;
    p.element_size_m = 0.2;
    const Dipper plain = make_dipper(p);
    p.wear_bars = WearBars::Transverse;
    const Dipper bars90 = make_dipper(p);
    p.wear_bars = WearBars::Diagonal;
    const Dipper bars45 = make_dipper(p);
    const std::size_t base = plain.body.plates.size();
    REQUIRE(bars90.body.plates.size() > base + 3);
    REQUIRE(bars45.body.plates.size() > base + 3);
    for (const Dipper* d : {&bars90, &bars45}) {
        check_plates_closed(d->body);
        for (std::size_t k = base; k < d->body.plates.size(); ++k) {
            const Plate& bar = d->body.plates[k];
            CAPTURE(k);
            CHECK(bar.normal().z == Approx(1.0));             // a bar's top faces into the dipper
            CHECK(bar.thickness_m == Approx(p.bar_height_m));  // and stands on the bottom
            for (const Vec3& c : bar.corners_m) {             // within the floor behind the lip
                CHECK(c.x >= -1e-9);
                CHECK(c.x <= p.bottom_length_m - p.lip_length_m + 1e-9);
                CHECK(std::abs(c.y) <= p.width_m / 2 + 1e-9);
            }
            const Vec3 e1 = bar.corners_m[1] - bar.corners_m[0], e2 = bar.corners_m[3] - bar.corners_m[0];
            const Vec3 length = norm(e1) > norm(e2) ? e1 : e2;  // the bar's long side
            const double angle = std::atan2(std::abs(length.y), std::abs(length.x)) * 180.0 / M_PI;
            CHECK(angle == Approx(d == &bars90 ? 90.0 : 45.0).margin(1e-9));  // to the flow (x)
        }
    }
}

TEST_CASE("feeder, truck body and ground have their stated sizes and closed plates", "[meshes][machine][unit]")
{
    const Feeder f = make_feeder({});
    check_plates_closed(f.pan);
    check_plates_closed(f.bin);
    double floor_area = 0.0;
    for (std::size_t t = 0; t < f.pan.surface.triangle_count(); ++t)
        if (f.pan.triangle_plate[t] < 3 && f.pan.triangle_on_face[t]) floor_area += f.pan.surface.triangle_area_m2(t);
    CHECK(floor_area == Approx(5.3 * 1.8).epsilon(1e-12));
    const MachinePart truck = make_truck_body({});
    check_plates_closed(truck);
    CHECK(truck.surface.bounds_max_m().z == Approx(2.2));
    const MachinePart ground = make_ground(20.0, 10.0, 1.0);
    CHECK(ground.surface.bounds_max_m().z == 0.0);
    CHECK(ground.surface.bounds_max_m().x == Approx(10.0));
}

TEST_CASE("machine geometry: bad parameters are errors naming them", "[meshes][machine][unit][bad_input]")
{
    DipperParameters p;
    p.rake_angle_deg = 20.0;
    CHECK_THROWS_WITH(make_dipper(p), Catch::Contains("rake_angle_deg") && Catch::Contains("20"));
    p = {};
    p.bar_pitch_m = 0.1;
    CHECK_THROWS_WITH(make_dipper(p), Catch::Contains("bar_pitch_m"));
    p = {};
    p.width_m = -4.0;
    CHECK_THROWS_WITH(make_dipper(p), Catch::Contains("width_m"));
    const Plate twisted{{Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{1, 1, 0.3}, Vec3{0, 1, 0}}, 0.1};
    CHECK_THROWS_WITH(make_part("bent", {twisted}, 0.1), Catch::Contains("part 'bent', plate 0") && Catch::Contains("not in one plane"));
    const Plate crossed{{Vec3{0, 0, 0}, Vec3{1, 1, 0}, Vec3{1, 0, 0}, Vec3{0, 1, 0}}, 0.1};
    CHECK_THROWS_WITH(make_part("crossed", {crossed}, 0.1), Catch::Contains("not convex"));
    CHECK_THROWS_WITH(make_part("thin", {box_plate({0, 0, 0}, {1, 1, 0})}, 0.1), Catch::Contains("thickness_m"));
}
