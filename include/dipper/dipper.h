// dipper's public API in one header: #include <dipper/dipper.h> and link dipper::dipper (docs/library.md).
// Each layer's headers can be included on their own too ("dem/world.h" with dipper::dem, and so on).
#pragma once

// core: vectors, errors, checkpoint streams, contact records
#include "core/contact_record.h"
#include "core/errors.h"
#include "core/state_io.h"
#include "core/vec3.h"

// meshes: triangle meshes, mesh files, the dipper's and the machine's geometry
#include "meshes/machine_geometry.h"
#include "meshes/mesh_io.h"
#include "meshes/triangle_mesh.h"

// dem: the spheres
#include "dem/insertion.h"
#include "dem/material.h"
#include "dem/output.h"
#include "dem/pile.h"
#include "dem/world.h"

// rigid: Bullet's rocks, walls and the rope shovel
#include "rigid/convex_polyhedron.h"
#include "rigid/machine_path.h"
#include "rigid/motion_curves.h"
#include "rigid/rigid_world.h"
#include "rigid/rock_generator.h"
#include "rigid/rope_shovel.h"

// wear: laws, wear surfaces, calibration against measured wear
#include "wear/calibration.h"
#include "wear/laws.h"
#include "wear/wear_output.h"
#include "wear/wear_surface.h"

// coupling: the coupled step, mixed beds, and the dig (CoSimulation)
#include "coupling/bulk_density.h"
#include "coupling/co_simulation.h"
#include "coupling/coupled_world.h"
#include "coupling/mixed_bed.h"

// scenario: scenario files, runs and sweeps
#include "scenario/runner.h"
#include "scenario/scenario.h"
#include "scenario/simulation.h"
#include "scenario/sweep.h"
