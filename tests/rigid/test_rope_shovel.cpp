// The rope shovel: statics against a hand calculation, the rake angle of the posed model, slack ropes,
// tracking of the prescribed curves while digging through rocks, the default cycle, propel, and bad motion files.
#include "core/errors.h"
#include "meshes/machine_geometry.h"
#include "rigid/rigid_world.h"
#include "rigid/rock_generator.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>

using namespace dipper;
using namespace dipper::rigid;

namespace {

constexpr double kG = 9.81;

RigidWorld shovel_world()
{
    RigidWorld w;
    w.add_material("rock");
    w.add_material("steel");
    w.add_material("ground");
    w.set_pair("rock", "rock", kTable2RockFriction.rock, 0.0);
    w.set_pair("rock", "steel", kTable2RockFriction.bucket, 0.0);
    w.set_pair("rock", "ground", kTable2RockFriction.ground, 0.0);
    w.set_pair("steel", "ground", 0.5, 0.0);
    return w;
}

MotionCurves hold(double hoist, double crowd, double swing = 0.0, double door = 0.0)
{
    return MotionCurves::from_samples({{0.0, hoist, crowd, swing, door}, {1000.0, hoist, crowd, swing, door}}, "hold");
}

/// Centroid of the steel of some plates: each a prism of face area x thickness.
Vec3 plates_centroid(const std::vector<meshes::Plate>& plates)
{
    double volume = 0.0;
    Vec3 moment;
    for (const auto& p : plates) {
        const auto& c = p.corners_m;
        const double a1 = 0.5 * norm(cross(c[1] - c[0], c[2] - c[0])), a2 = 0.5 * norm(cross(c[2] - c[0], c[3] - c[0]));
        const Vec3 face = ((c[0] + c[1] + c[2]) * (a1 / 3.0) + (c[0] + c[2] + c[3]) * (a2 / 3.0)) * (1.0 / (a1 + a2));
        const double v = (a1 + a2) * p.thickness_m;
        volume += v;
        moment += (face - p.normal() * (p.thickness_m / 2.0)) * v;
    }
    return moment * (1.0 / volume);
}

std::string temp_file(const std::string& name, const std::string& text)
{
    const auto path = std::filesystem::temp_directory_path() / ("dipper_test_" + name);
    std::ofstream(path) << text;
    return path.string();
}

}  // namespace

TEST_CASE("the dipper at rest with an 80 t payload: hoist and crowd forces equal the hand statics (2 %)",
          "[rigid][shovel][statics][unit]")
{
    // Hand statics in the boom plane. The handle, dipper, door and payload turn together about the
    // shipper shaft S (the saddle hinge is free); the ropes pull the bail towards the sheave P.
    //   moments about S:   T (r_B x e)_y + sum m_i g (x_i - S_x) = 0     (gravity's moment is m g (x - S_x))
    //   along the handle:  F_crowd = -(W + T e) . u
    // with e the rope direction, u the handle axis. Positions come from the pure geometry (pose_shovel) at
    // the handle angle the model settled to, masses from the geometry parameters. Measured: at 0.14 deg
    // hoist 1.49727 MN and crowd 381.171 kN, both within 1e-5 of the hand values; at 30.2 deg hoist
    // +1.4e-5, crowd +1.6e-4.
    const meshes::Dipper dipper = meshes::make_dipper({});
    for (const double angle_guess : {0.0, 30.0}) {
        ShovelGeometry g;
        g.payload_kg = 80000.0;
        const double crowd = 7.0;
        const double hoist = pose_shovel(g, dipper, angle_guess, crowd).rope_length_m;
        RigidWorld w = shovel_world();
        w.add_rope_shovel(dipper, g, hold(hoist, crowd), w.material_index("steel"));
        for (int k = 0; k < 4000; ++k) w.step(1e-3);  // rope oscillation damped out (ratio 0.2, 3 Hz)
        const ShovelReading r = w.shovel_reading();
        CAPTURE(angle_guess, r.handle_angle_deg);

        const ShovelPose p = pose_shovel(g, dipper, r.handle_angle_deg, r.crowd_extension_m);
        const Vec3 S = p.shipper_shaft_m;
        const Mat3& R = p.dipper_rotation;
        const Vec3 O = p.dipper_origin_m;
        const auto& dp = dipper.parameters;
        // struck volume centroid of the trapezoid (0,0), (Lb,0), (Lt,H), (0,H): for 4, 3, 3 m it is
        // x = (Lb^2 + Lb Lt + Lt^2) / (3 (Lb + Lt)), z = H (Lb + 2 Lt) / (3 (Lb + Lt))
        const double lb = dp.bottom_length_m, lt = dp.top_length_m, h = dp.height_m;
        const Vec3 payload_local{(lb * lb + lb * lt + lt * lt) / (3.0 * (lb + lt)), 0.0, h * (lb + 2.0 * lt) / (3.0 * (lb + lt))};
        struct Mass { double m; Vec3 x; };
        const Mass masses[] = {
            {g.handle_mass_kg, S + p.handle_axis * (r.crowd_extension_m - g.handle_length_m / 2.0)},
            {g.dipper_mass_kg, O + R * plates_centroid(dipper.body.plates)},
            {g.door_mass_kg, O + R * (dipper.door_hinge_m + plates_centroid(dipper.door.plates))},
            {g.payload_kg, O + R * payload_local},
        };
        double gravity_moment = 0.0, total_mass = 0.0;
        for (const Mass& m : masses) {
            gravity_moment += m.m * kG * (m.x.x - S.x);
            total_mass += m.m;
        }
        const Vec3 bail = p.bail_m[0], e = normalized(p.sheave_m - bail);
        const Vec3 rb = bail - S;
        const double arm = rb.z * e.x - rb.x * e.z;  // y-moment of a unit pull along e at the bail
        const double hoist_hand = -gravity_moment / arm;  // both ropes together (x, z parts of e are shared)
        const Vec3 pull{hoist_hand * e.x, 0.0, hoist_hand * e.z};
        const double crowd_hand = -dot(Vec3{0.0, 0.0, -total_mass * kG} + pull, p.handle_axis);

        CHECK(r.hoist_force_N == Approx(hoist_hand).epsilon(0.02));
        CHECK(r.crowd_force_N == Approx(crowd_hand).epsilon(0.02));
        CHECK(r.rope_tension_N[0] == Approx(r.rope_tension_N[1]).epsilon(1e-9));
    }
}

TEST_CASE("the rake angle measured on the posed model equals the configured one", "[rigid][shovel][unit]")
{
    for (const double rake : {57.8, 61.8, 65.8}) {
        meshes::DipperParameters dp;
        dp.rake_angle_deg = rake;
        dp.element_size_m = 0.3;
        const meshes::Dipper dipper = meshes::make_dipper(dp);
        ShovelGeometry g;
        RigidWorld w = shovel_world();
        w.add_rope_shovel(dipper, g, default_loading_cycle(g, dipper), w.material_index("steel"));
        for (int k = 0; k < 20000; ++k) {  // through the dig and the swing: many poses
            w.step(1e-3);
            if (k % 1000 == 0) CHECK(w.shovel_reading().rake_angle_deg == Approx(rake).margin(1e-6));
        }
    }
}

TEST_CASE("a rope never pushes: paid out beyond reach, the dipper rests on the ground and the ropes carry 0",
          "[rigid][shovel][unit]")
{
    const meshes::Dipper dipper = meshes::make_dipper({});
    ShovelGeometry g;
    RigidWorld w = shovel_world();
    w.add_ground_plane(0.0, w.material_index("ground"), "ground");
    // ropes 3 m longer than needed to hold the dipper at 60 deg: it swings down onto the ground
    const double hoist = pose_shovel(g, dipper, 60.0, 8.0).rope_length_m + 3.0;
    w.add_rope_shovel(dipper, g, hold(hoist, 8.0), w.material_index("steel"));
    int slack_steps = 0;
    for (int k = 0; k < 4000; ++k) {
        w.step(1e-3);
        const ShovelReading& r = w.shovel_reading();
        CHECK(r.rope_tension_N[0] >= 0.0);
        CHECK(r.rope_tension_N[1] >= 0.0);
        if (r.rope_length_m[0] < hoist) {
            ++slack_steps;
            CHECK(r.rope_tension_N[0] == 0.0);
            CHECK(r.hoist_force_N == 0.0);
        }
    }
    CHECK(slack_steps > 3000);
    CHECK(w.shovel_reading().rope_length_m[0] < hoist - 0.1);  // resting on the ground, the rope hangs slack
}

TEST_CASE("the default cycle: three passes in 138 s with 15 s digs, the shovel follows it", "[rigid][shovel][unit]")
{
    const meshes::Dipper dipper = meshes::make_dipper({});
    ShovelGeometry g;
    const MotionCurves cycle = default_loading_cycle(g, dipper);
    CHECK(cycle.duration_s() == Approx(137.99));
    for (int pass = 0; pass < 3; ++pass) {
        const double t0 = 46.0 * pass;
        CHECK(cycle.at(t0).hoist_length_m > cycle.at(t0 + 15.0).hoist_length_m + 8.0);  // hoisting in while digging
        CHECK(cycle.at(t0 + 26.0).door_deg == Approx(60.0));                               // dumping
        CHECK(cycle.at(t0 + 25.0).swing_deg == Approx(90.0));
    }
    // tracking without load: crowd to 1e-6 m (a position motor) and swing to 1e-6 deg through the whole pass.
    // The drives never have to jump to a new speed (the curves are smooth), so the crowd's 20 MN keeps the
    // 80 t of handle, dipper and door on its curve also while returning to the toe (measured: exact; with
    // key poses joined by straight lines it lagged 4.2 mm there)
    RigidWorld w = shovel_world();
    w.add_rope_shovel(dipper, g, cycle, w.material_index("steel"));
    double crowd_error = 0.0, swing_error = 0.0;
    for (int k = 0; k < 46000; ++k) {
        w.step(1e-3);
        const ShovelReading& r = w.shovel_reading();
        const MotionSample m = cycle.at(r.time_s);
        crowd_error = std::max(crowd_error, std::abs(r.crowd_extension_m - m.crowd_extension_m));
        swing_error = std::max(swing_error, std::abs(r.swing_deg - m.swing_deg));
    }
    CHECK(crowd_error < 1e-6);
    CHECK(swing_error < 1e-6);
}

TEST_CASE("the built-in cycles move smoothly: every drive accelerates and brakes, none jumps to a new speed",
          "[rigid][shovel][unit]")
{
    // Second differences of the sampled curves (samples at most 0.05 s apart) bound each drive's
    // acceleration. Joined by straight lines, the swing would start at 9 deg/s at once: 180 deg/s^2 over one
    // 0.05 s interval, 3 m/s sideways for the dipper 20 m out. Smooth: a swing of 90 deg in 10 s from rest to
    // rest peaks at 6 x 90 / 10^2 = 5.4 deg/s^2 (the return, 45 deg in 5 s then 4 s, at 11.6); hoist and
    // crowd stay within 4 m/s^2, the door (60 deg in 1 s) within 6 x 60 = 360 deg/s^2. Key poses are kept
    // exactly, and the dig comes to rest at its end (15 s into each pass).
    const meshes::Dipper dipper = meshes::make_dipper({});
    ShovelGeometry g;
    for (const MotionCurves& cycle : {default_loading_cycle(g, dipper, 2.0), dig_and_return_cycle(g, dipper, 3)}) {
        const auto& s = cycle.samples();
        double hoist = 0.0, crowd = 0.0, swing = 0.0, door = 0.0, propel = 0.0, spacing = 0.0;
        for (std::size_t k = 1; k + 1 < s.size(); ++k) {
            const double h0 = s[k].time_s - s[k - 1].time_s, h1 = s[k + 1].time_s - s[k].time_s;
            spacing = std::max(spacing, h1);
            const auto acceleration = [&](double MotionSample::*y) {
                return std::abs((s[k + 1].*y - s[k].*y) / h1 - (s[k].*y - s[k - 1].*y) / h0) / (0.5 * (h0 + h1));
            };
            hoist = std::max(hoist, acceleration(&MotionSample::hoist_length_m));
            crowd = std::max(crowd, acceleration(&MotionSample::crowd_extension_m));
            swing = std::max(swing, acceleration(&MotionSample::swing_deg));
            door = std::max(door, acceleration(&MotionSample::door_deg));
            propel = std::max(propel, acceleration(&MotionSample::propel_m));
        }
        CHECK(spacing <= 0.05 + 1e-12);
        CHECK(hoist < 4.0);
        CHECK(crowd < 4.0);
        CHECK(swing < 12.0);
        CHECK(door < 360.0);
        CHECK(propel < 0.2);
        // no overshoot: the swing stays within 0-90 deg and the door within 0-60 deg, and the hoist rope
        // only shortens through each dig (the handle angle falls monotonically between its key poses)
        const double period = cycle.duration_s() > 100.0 ? kDefaultCyclePass_s : kDigAndReturnPass_s;
        for (std::size_t k = 0; k < s.size(); ++k) {
            CHECK(s[k].swing_deg >= -1e-12);
            CHECK(s[k].swing_deg <= 90.0 + 1e-12);
            CHECK(s[k].door_deg >= -1e-12);
            CHECK(s[k].door_deg <= 60.0 + 1e-12);
            const double local = s[k].time_s - period * std::floor(s[k].time_s / period + 1e-9);
            if (k > 0 && local > 1e-9 && local <= kBuiltInDig_s + 1e-9)
                CHECK(s[k].hoist_length_m <= s[k - 1].hoist_length_m + 1e-12);
        }
        // between two resting keys the curve is the closed form y0 + (y1 - y0)(3u^2 - 2u^3): the swing of the
        // default cycle from 0 deg at 15 s to 90 deg at 25 s (samples fall on u = 0.25 and 0.5)
        if (period == kDefaultCyclePass_s)
            for (int pass = 0; pass < 3; ++pass) {
                CHECK(cycle.at(pass * period + 17.5).swing_deg == Approx(90.0 * (3.0 * 0.0625 - 2.0 * 0.015625)).margin(1e-9));
                CHECK(cycle.at(pass * period + 20.0).swing_deg == Approx(45.0).margin(1e-9));
            }
        for (int pass = 0; pass < 3; ++pass) {
            const double end = pass * period + kBuiltInDig_s;
            const MotionSample a = cycle.at(end - 0.05), b = cycle.at(end), c = cycle.at(end + 0.05);
            // at rest at the dig's end: the hoist's speed on either side is what 4 m/s^2 allows in 0.05 s
            CHECK(std::abs(b.hoist_length_m - a.hoist_length_m) / 0.05 < 0.2);
            CHECK(std::abs(c.hoist_length_m - b.hoist_length_m) / 0.05 < 0.2);
        }
    }
}

TEST_CASE("the shovel follows its curves while digging through a rock pile", "[rigid][shovel][rocks][unit]")
{
    // 60 rocks of 300-600 mm dropped at the toe of the dig; the first 8 s of the dig. The crowd is a position
    // motor: within 1 mm. The ropes are elastic: the measured length exceeds the paid-out length by the
    // stretch T / k (k = EA / L), which the test bounds by the largest tension seen plus 2 cm of dynamics.
    // Measured: crowd within 2.8e-6 m; rope length 4.7 cm over the paid-out length with 3.9 cm of stretch.
    const meshes::Dipper dipper = meshes::make_dipper({});
    ShovelGeometry g;
    const MotionCurves cycle = default_loading_cycle(g, dipper);
    RigidWorld w = shovel_world();
    w.add_ground_plane(0.0, w.material_index("ground"), "ground");
    for (int k = 0; k < 60; ++k) {
        const int i = k % 6, j = (k / 6) % 5, layer = k / 30;
        const ConvexPolyhedron r = generate_rock({0.3 + 0.1 * (k % 4), 1.0, 1.8, 18}, 500 + static_cast<std::uint64_t>(k));
        w.add_rock(r, 2700.0, w.material_index("rock"), {18.0 + 0.75 * i, -1.9 + 0.95 * j, 0.5 + 0.75 * layer});
    }
    double crowd_error = 0.0, excess = 0.0, stretch_bound = 0.0, peak_dig = 0.0;
    int dipper_contacts = 0;
    const RigidWorld::ShovelParts parts = w.add_rope_shovel(dipper, g, cycle, w.material_index("steel"));
    for (int k = 0; k < 8000; ++k) {
        w.step(1e-3);
        const ShovelReading& r = w.shovel_reading();
        const MotionSample m = cycle.at(r.time_s);
        crowd_error = std::max(crowd_error, std::abs(r.crowd_extension_m - m.crowd_extension_m));
        const double k_rope = g.rope_axial_stiffness_N / m.hoist_length_m;
        excess = std::max(excess, r.rope_length_m[0] - m.hoist_length_m);
        stretch_bound = std::max(stretch_bound, r.rope_tension_N[0] / k_rope);
        peak_dig = std::max(peak_dig, r.dig_force_filtered_N);
        // contact records on the dipper name the dipper surface triangle under the contact point
        const std::vector<ContactRecord> records = w.surface_contacts(parts.dipper, 7, &dipper.body.surface);
        dipper_contacts += static_cast<int>(records.size());
        if (!records.empty()) {
            Mat3 rotation;
            Vec3 origin;
            w.dipper_pose(rotation, origin);
            for (const ContactRecord& c : records) {
                REQUIRE(c.triangle_id >= 0);
                REQUIRE(static_cast<std::size_t>(c.triangle_id) < dipper.body.surface.triangle_count());
                CHECK(c.surface_id == 7);
                CHECK(c.normal_force_N >= 0.0);
                const Vec3 local = rotation.transposed() * (c.point_world - origin);
                const auto& t = dipper.body.surface.triangles()[static_cast<std::size_t>(c.triangle_id)];
                const auto& x = dipper.body.surface.vertices_m();
                CHECK(std::sqrt(meshes::closest_point_on_triangle(local, x[t[0]], x[t[1]], x[t[2]]).distance_squared) < 0.02);
            }
        }
    }
    CHECK(crowd_error < 1e-3);
    CHECK(excess < stretch_bound + 0.02);
    CHECK(dipper_contacts > 0);  // it did dig through rocks
}

TEST_CASE("motion files are joined by monotone cubics: samples kept, velocity continuous, no overshoot, rest at turns",
          "[rigid][shovel][unit]")
{
    // A coarse file of four samples 10 s apart: the crowd runs out at changing speed, the swing goes out and
    // stands, the hoist pays in and then out again (it turns back at 20 s). Straight lines between the
    // samples would change each drive's speed at once at a sample: the crowd by 0.2 m/s at 10 s.
    const std::string text = "time_s,hoist_length_m,crowd_extension_m,swing_deg,door_deg\n"
                             "0,15,5,0,0\n10,12,8,45,0\n20,10,9,90,0\n30,12,9.5,90,0\n";
    const MotionCurves m = MotionCurves::from_csv(temp_file("motion_coarse.csv", text));
    const double times[4] = {0.0, 10.0, 20.0, 30.0};
    const auto pick = [](const MotionSample& s, int drive) {
        return drive == 0 ? s.hoist_length_m : drive == 1 ? s.crowd_extension_m : s.swing_deg;
    };
    const auto value = [&](double t, int drive) { return pick(m.at(t), drive); };
    // one-sided speeds over 1e-5 s: their error is about 1e-5 s times the acceleration (below 0.1 per s^2
    // here), so 1e-5 bounds a real jump; straight lines would jump by up to 4.5 per second (the swing at 20 s)
    const double h = 1e-5;
    const auto left = [&](double t, int drive) { return (value(t, drive) - value(t - h, drive)) / h; };
    const auto right = [&](double t, int drive) { return (value(t + h, drive) - value(t, drive)) / h; };
    for (int drive = 0; drive < 3; ++drive) {
        CAPTURE(drive);
        for (int k = 0; k < 4; ++k) CHECK(value(times[k], drive) == pick(m.samples()[static_cast<std::size_t>(k)], drive));
        for (int k = 1; k < 3; ++k) CHECK(std::abs(left(times[k], drive) - right(times[k], drive)) < 1e-5);
        CHECK(std::abs(right(0.0, drive)) < 1e-5);  // starts from rest
        CHECK(std::abs(left(30.0, drive)) < 1e-5);  // ends at rest
        // between two samples the drive stays between their values (to round-off)
        for (int k = 0; k < 3; ++k) {
            const double lo = std::min(value(times[k], drive), value(times[k + 1], drive));
            const double hi = std::max(value(times[k], drive), value(times[k + 1], drive));
            for (int j = 1; j < 100; ++j) {
                const double v = value(times[k] + 0.1 * j, drive);
                CHECK(v >= lo - 1e-12);
                CHECK(v <= hi + 1e-12);
            }
        }
    }
    CHECK(std::abs(left(20.0, 0)) < 1e-5);   // the hoist rests where it turns back
    CHECK(std::abs(right(20.0, 0)) < 1e-5);
    CHECK(std::abs(right(20.0, 2)) < 1e-5);  // the swing rests where it comes to stand
    CHECK(right(10.0, 1) > 0.1);             // the crowd keeps moving through 10 s, at a continuous speed

    // a drive that stands keeps its value to the last bit (the pass tracker reads a hauling hoist from it)
    const MotionCurves stand = MotionCurves::from_samples({{0.0, 13.7, 7.5, 0.0, 0.0}, {2.0, 13.7, 7.5, 0.0, 0.0}, {2.3, 13.7, 7.5, 0.0, 30.0}}, "stand");
    for (double t = 0.0; t < 2.3; t += 0.01) CHECK(stand.at(t).hoist_length_m == 13.7);

    // interior samples on a straight line give the line between them
    std::vector<MotionSample> line;
    for (int k = 0; k < 6; ++k) line.push_back({double(k), 10.0 + 0.5 * k, 5.0 + 0.25 * k, 3.0 * k, 0.0, 0.1 * k});
    const MotionCurves straight = MotionCurves::from_samples(line, "line");
    for (double t = 1.0; t <= 4.0; t += 0.125) {
        CHECK(straight.at(t).hoist_length_m == Approx(10.0 + 0.5 * t).epsilon(1e-14));
        CHECK(straight.at(t).swing_deg == Approx(3.0 * t).epsilon(1e-14));
        CHECK(straight.at(t).propel_m == Approx(0.1 * t).epsilon(1e-14));
    }
}

TEST_CASE("motion files: unsorted times, missing columns and NaN are errors naming file, line and value",
          "[rigid][shovel][unit][bad_input]")
{
    const std::string header = "time_s,hoist_length_m,crowd_extension_m,swing_deg,door_deg\n";
    const auto ok = MotionCurves::from_csv(temp_file("motion_ok.csv", header + "0,15,8,0,0\n10,7,7.5,0,0\n"));
    CHECK(ok.at(5.0).hoist_length_m == Approx(11.0));  // half-way between two samples (the cubic is symmetric)
    CHECK(ok.at(-1.0).crowd_extension_m == 8.0);
    CHECK(ok.at(99.0).crowd_extension_m == 7.5);
    CHECK_THROWS_WITH(MotionCurves::from_csv(temp_file("motion_unsorted.csv", header + "0,15,8,0,0\n10,7,7.5,0,0\n5,9,8,0,0\n")),
                      Catch::Contains("motion_unsorted.csv:4") && Catch::Contains("time_s 5") && Catch::Contains("increase"));
    CHECK_THROWS_WITH(MotionCurves::from_csv(temp_file("motion_missing.csv", "time_s,hoist_length_m,crowd_extension_m,swing_deg\n0,15,8,0\n")),
                      Catch::Contains("motion_missing.csv:1") && Catch::Contains("lacks column 'door_deg'"));
    CHECK_THROWS_WITH(MotionCurves::from_csv(temp_file("motion_nan.csv", header + "0,15,8,0,0\n10,nan,7.5,0,0\n")),
                      Catch::Contains("motion_nan.csv:3") && Catch::Contains("hoist_length_m") && Catch::Contains("'nan'"));
    CHECK_THROWS_WITH(MotionCurves::from_csv(temp_file("motion_negative.csv", header + "0,15,8,0,0\n10,-2,7.5,0,0\n")),
                      Catch::Contains("motion_negative.csv:3") && Catch::Contains("hoist_length_m is -2"));
    CHECK_THROWS_WITH(MotionCurves::from_csv(temp_file("motion_empty.csv", "")), Catch::Contains("is empty"));
    CHECK_THROWS_WITH(MotionCurves::from_csv("/nonexistent/motion.csv"), Catch::Contains("cannot open motion file"));
    // a first hoist length too short to reach the dipper at that crowd
    const meshes::Dipper dipper = meshes::make_dipper({});
    RigidWorld w = shovel_world();
    CHECK_THROWS_WITH(w.add_rope_shovel(dipper, {}, hold(2.0, 8.0), w.material_index("steel")),
                      Catch::Contains("first hoist length 2 m cannot hold the dipper"));
}

TEST_CASE("propel: the machine moves along its heading as the curve says, and the links keep their pose to it",
          "[rigid][shovel][unit]")
{
    // optional column: absent is 0, present is interpolated like the others
    const std::string header = "time_s,hoist_length_m,crowd_extension_m,swing_deg,door_deg";
    const auto still = MotionCurves::from_csv(temp_file("motion_still.csv", header + "\n0,15,8,0,0\n10,7,7.5,0,0\n"));
    CHECK(still.at(5.0).propel_m == 0.0);
    const auto moving = MotionCurves::from_csv(temp_file("motion_propel.csv", header + ",propel_m\n0,15,8,0,0,0\n10,7,7.5,0,0,3\n"));
    CHECK(moving.at(5.0).propel_m == Approx(1.5));
    CHECK_THROWS_WITH(MotionCurves::from_csv(temp_file("motion_twice.csv", header + ",door_deg\n0,15,8,0,0,0\n")),
                      Catch::Contains("motion_twice.csv:1") && Catch::Contains("'door_deg' appears twice"));
    CHECK_THROWS_WITH(MotionCurves::from_csv(temp_file("motion_typo.csv", header + ",propel\n0,15,8,0,0,0\n")),
                      Catch::Contains("unknown column 'propel'") && Catch::Contains("optionally propel_m"));

    // the same hold with and without 2 m of propel between 0.1 s and 0.5 s, heading 30 deg: after it the
    // dipper stands 2 m further along the heading, turned the same; the links feel no base acceleration
    // (the base is fixed to the ground and placed), so the difference is round-off
    const meshes::Dipper dipper = meshes::make_dipper({});
    const ShovelGeometry g;
    const double hoist = pose_shovel(g, dipper, 30.0, 8.0).rope_length_m;
    const MotionCurves still_hold = MotionCurves::from_samples({{0.0, hoist, 8.0, 0.0, 0.0}, {10.0, hoist, 8.0, 0.0, 0.0}}, "hold");
    const MotionCurves propel_hold = MotionCurves::from_samples(
        {{0.0, hoist, 8.0, 0.0, 0.0, 0.0}, {0.1, hoist, 8.0, 0.0, 0.0, 0.0}, {0.5, hoist, 8.0, 0.0, 0.0, 2.0}, {10.0, hoist, 8.0, 0.0, 0.0, 2.0}},
        "hold and propel");
    const Vec3 start{5.0, -3.0, 0.0};
    RigidWorld a = shovel_world(), b = shovel_world();
    a.add_rope_shovel(dipper, g, still_hold, a.material_index("steel"), start, 30.0);
    b.add_rope_shovel(dipper, g, propel_hold, b.material_index("steel"), start, 30.0);
    const Vec3 forward{std::cos(30.0 * M_PI / 180.0), std::sin(30.0 * M_PI / 180.0), 0.0};
    for (int k = 0; k < 600; ++k) {
        a.step(1e-3);
        b.step(1e-3);
        if (k == 299) {  // t = 0.3 s: halfway
            Mat3 ra, rb;
            Vec3 oa, ob;
            a.dipper_pose(ra, oa);
            b.dipper_pose(rb, ob);
            CHECK(norm(ob - oa - forward * 1.0) < 1e-6);
        }
    }
    Mat3 ra, rb;
    Vec3 oa, ob;
    a.dipper_pose(ra, oa);
    b.dipper_pose(rb, ob);
    CHECK(norm(ob - oa - forward * 2.0) < 1e-6);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) CHECK(rb.m[i][j] == Approx(ra.m[i][j]).margin(1e-9));
    CHECK(b.shovel_reading().hoist_force_N == Approx(a.shovel_reading().hoist_force_N).epsilon(1e-6));

    // the default cycle advancing 2.5 m per pass: the same poses, the propel done while swinging back
    const MotionCurves fixed = default_loading_cycle(g, dipper), advancing = default_loading_cycle(g, dipper, 2.5);
    for (int pass = 0; pass < 3; ++pass) {
        const double t0 = 46.0 * pass;
        CHECK(advancing.at(t0 + 7.0).propel_m == Approx(2.5 * pass));  // digging: standing
        CHECK(advancing.at(t0 + 27.0).propel_m == Approx(2.5 * pass));  // dumping: standing
        CHECK(advancing.at(t0 + 34.5).propel_m == Approx(2.5 * (pass + 0.5)));  // steadily from 28 s to 41 s
        CHECK(advancing.at(t0 + 42.0).propel_m == Approx(2.5 * (pass + 1)));
        CHECK(advancing.at(t0 + 34.5).hoist_length_m == Approx(fixed.at(t0 + 34.5).hoist_length_m).epsilon(1e-12));
    }
    CHECK_THROWS_WITH(default_loading_cycle(g, dipper, -1.0), Catch::Contains("advance_per_pass_m = -1"));
}

TEST_CASE("a wall that does not block the machine leaves the shovel as if it were not there, one that does, stops it",
          "[rigid][shovel][unit]")
{
    // the dipper holds a pose with a fixed box through its middle: let through, the drive forces equal
    // those of the same pose without the box (to round-off); blocked, contact changes them
    const meshes::Dipper dipper = meshes::make_dipper({});
    const ShovelGeometry g;
    const ShovelPose pose = pose_shovel(g, dipper, 30.0, 8.0);
    const MotionCurves hold_pose = hold(pose.rope_length_m, 8.0);
    const Vec3 centre = pose.dipper_origin_m + pose.dipper_rotation * Vec3{2.0, 0.0, 0.5};
    const meshes::TriangleMesh box = meshes::make_box_mesh(centre - Vec3{0.3, 3.0, 0.3}, centre + Vec3{0.3, 3.0, 0.3});
    const auto forces_after = [&](int walls) {  // 0: none, 1: let through, 2: blocking
        RigidWorld w = shovel_world();
        if (walls > 0) {
            const BodyId id = w.add_static_mesh(box, w.material_index("steel"), "box");
            if (walls == 1) w.set_blocks_machine(id, false);
        }
        w.add_rope_shovel(dipper, g, hold_pose, w.material_index("steel"));
        for (int k = 0; k < 300; ++k) w.step(1e-3);
        return std::make_pair(w.shovel_reading().hoist_force_filtered_N, w.shovel_reading().crowd_force_filtered_N);
    };
    const auto free = forces_after(0), through = forces_after(1), blocked = forces_after(2);
    CHECK(through.first == Approx(free.first).epsilon(1e-9));
    CHECK(through.second == Approx(free.second).margin(1e-6 * std::abs(free.first)));
    CHECK(std::abs(blocked.first - free.first) + std::abs(blocked.second - free.second) > 0.01 * free.first);
    RigidWorld w = shovel_world();
    const BodyId rock = w.add_rock(generate_rock({0.4, 1.0, 1.2, 20}, 3), 2700.0, w.material_index("rock"), {0, 0, 5});
    CHECK_THROWS_WITH(w.set_blocks_machine(rock, false), Catch::Contains("is not fixed or kinematic"));
}
