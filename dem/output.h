// What a DEM run writes: VTK XML files that ParaView reads (particles, wall meshes), a .pvd collection
// that strings them into a time series, and CSV time series of global quantities.
#pragma once

#include "dem/world.h"

#include <fstream>
#include <string>
#include <vector>

namespace dipper::dem {

/// Writes the particles as VTK XML PolyData (.vtp): points with radius_m, velocity_m_per_s,
/// angular_velocity_rad_per_s, material and id.
void write_particles_vtp(const World& world, const std::string& path);
/// Writes a mesh wall in its current world pose as VTK XML PolyData (.vtp).
void write_mesh_vtp(const MeshWall& wall, const std::string& path);

/// A ParaView collection (.pvd) of files over time; rewritten whole after each entry so that it is
/// valid even if the run stops.
class PvdCollection {
public:
    explicit PvdCollection(std::string path) : path_(std::move(path)) {}
    /// Records that `file` (relative to the .pvd's folder) holds the state at time_s.
    void add(double time_s, const std::string& file);
    /// The entries so far, and setting them back (a resumed run drops what came after its checkpoint).
    const std::vector<std::pair<double, std::string>>& entries() const { return entries_; }
    void restore(std::vector<std::pair<double, std::string>> entries);

private:
    void rewrite() const;
    std::string path_;
    std::vector<std::pair<double, std::string>> entries_;
};

/// A series of particle (and mesh) snapshots in one folder: particles_000000.vtp ..., particles.pvd,
/// and one series per mesh wall.
class ParaViewSeries {
public:
    explicit ParaViewSeries(std::string directory);
    void write(const World& world);

private:
    std::string dir_;
    int index_ = 0;
    PvdCollection particles_;
    std::vector<PvdCollection> meshes_;
};

/// CSV time series of the world: time, kinetic energy, contact counts, largest overlap, wall forces.
class WorldCsv {
public:
    WorldCsv(const std::string& path, const World& world);
    void write_row(const World& world);

private:
    std::ofstream out_;
    std::string path_;
};

}  // namespace dipper::dem
