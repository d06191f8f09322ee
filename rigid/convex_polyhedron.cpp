#include "rigid/convex_polyhedron.h"

#include "core/errors.h"

#include <LinearMath/btConvexHullComputer.h>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

static_assert(sizeof(btScalar) == sizeof(double), "dipper links Bullet's double-precision build (BT_USE_DOUBLE_PRECISION)");

namespace dipper::rigid {

namespace {

Mat3 outer(const Vec3& a, const Vec3& b)
{
    Mat3 m;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) m.m[i][j] = a[i] * b[j];
    return m;
}

Mat3 add(const Mat3& a, const Mat3& b, double scale = 1.0)
{
    Mat3 r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) r.m[i][j] = a.m[i][j] + scale * b.m[i][j];
    return r;
}

Mat3 zero_matrix()
{
    Mat3 z;
    for (auto& row : z.m)
        for (double& v : row) v = 0.0;
    return z;
}

double bounding_diagonal(const std::vector<Vec3>& x)
{
    Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
    for (const Vec3& v : x) {
        lo = {std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z)};
        hi = {std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z)};
    }
    return norm(hi - lo);
}

}  // namespace

ConvexPolyhedron ConvexPolyhedron::hull_of(const std::vector<Vec3>& points, const std::string& source)
{
    if (points.size() < 4)
        throw InputError(concat(source, ": a rock needs at least 4 points; got ", points.size()));
    std::vector<double> coords;
    coords.reserve(points.size() * 3);
    for (std::size_t k = 0; k < points.size(); ++k) {
        if (!is_finite(points[k])) throw InputError(concat(source, ": point ", k, " is not finite"));
        coords.insert(coords.end(), {points[k].x, points[k].y, points[k].z});
    }
    btConvexHullComputer hull;
    hull.compute(coords.data(), static_cast<int>(3 * sizeof(double)), static_cast<int>(points.size()), 0.0, 0.0);

    ConvexPolyhedron p;
    p.source_ = source;
    for (int k = 0; k < hull.vertices.size(); ++k)
        p.vertices_m_.push_back({hull.vertices[k].x(), hull.vertices[k].y(), hull.vertices[k].z()});
    if (p.vertices_m_.size() < 4)
        throw InputError(concat(source, ": the points span no volume (their hull has ", p.vertices_m_.size(), " vertices)"));
    Vec3 mean;
    for (const Vec3& v : p.vertices_m_) mean += v;
    mean = mean * (1.0 / static_cast<double>(p.vertices_m_.size()));
    for (int f = 0; f < hull.faces.size(); ++f) {
        std::vector<std::uint32_t> polygon;
        const btConvexHullComputer::Edge* start = &hull.edges[hull.faces[f]];
        const btConvexHullComputer::Edge* e = start;
        do {
            polygon.push_back(static_cast<std::uint32_t>(e->getTargetVertex()));
            e = e->getNextEdgeOfFace();
        } while (e != start && polygon.size() <= p.vertices_m_.size());
        for (std::size_t k = 1; k + 1 < polygon.size(); ++k) {
            std::array<std::uint32_t, 3> t{polygon[0], polygon[k], polygon[k + 1]};
            const Vec3 a = p.vertices_m_[t[0]], b = p.vertices_m_[t[1]], c = p.vertices_m_[t[2]];
            const Vec3 n = cross(b - a, c - a);
            if (norm(n) == 0.0) continue;
            if (dot(n, (a + b + c) * (1.0 / 3.0) - mean) < 0.0) std::swap(t[1], t[2]);
            p.triangles_.push_back(t);
        }
    }
    p.compute_properties();
    const double diag = bounding_diagonal(p.vertices_m_);
    if (!(p.volume_m3_ > 1e-9 * diag * diag * diag))
        throw InputError(concat(source, ": the points span no volume (hull volume ", p.volume_m3_, " m^3 for a size of ",
                                diag, " m); a rock must be a solid"));
    return p;
}

ConvexPolyhedron ConvexPolyhedron::from_mesh(const meshes::TriangleMesh& mesh)
{
    const std::string& source = mesh.source();
    // closed: every edge is shared by exactly two triangles
    std::vector<int> uses(mesh.edge_count(), 0);
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t)
        for (const std::uint32_t e : mesh.triangle_edges(t)) ++uses[e];
    for (std::size_t e = 0; e < uses.size(); ++e)
        if (uses[e] != 2)
            throw InputError(concat(source, ": the rock mesh is not closed: edge ", e, " (vertices ", mesh.edge_vertices(e)[0],
                                    ", ", mesh.edge_vertices(e)[1], ") belongs to ", uses[e],
                                    " triangles; expected 2"));
    ConvexPolyhedron p;
    p.source_ = source;
    p.vertices_m_ = mesh.vertices_m();
    p.triangles_ = mesh.triangles();
    p.compute_properties();
    const double diag = bounding_diagonal(p.vertices_m_);
    if (!(p.volume_m3_ > 1e-9 * diag * diag * diag))
        throw InputError(concat(source, ": the rock mesh encloses volume ", p.volume_m3_, " m^3 for a size of ", diag,
                                " m; expected a solid with outward-facing triangles"));
    const double tolerance = 1e-6 * diag;
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        const Vec3 n = mesh.triangle_normal(t);
        const Vec3 a = p.vertices_m_[mesh.triangles()[t][0]];
        for (std::size_t v = 0; v < p.vertices_m_.size(); ++v) {
            const double out = dot(n, p.vertices_m_[v] - a);
            if (out > tolerance)
                throw InputError(concat(source, ": the rock mesh is not convex: vertex ", v, " lies ", out,
                                        " m outside the plane of triangle ", t, " (tolerance ", tolerance,
                                        " m); rocks must be convex polyhedra"));
        }
    }
    return p;
}

void ConvexPolyhedron::compute_properties()
{
    // signed tetrahedra from a reference point inside: volume, first and second moments (exact for a
    // closed, consistently oriented surface; Tonon 2004, the canonical tetrahedron's covariance)
    Vec3 ref;
    for (const Vec3& v : vertices_m_) ref += v;
    ref = ref * (1.0 / static_cast<double>(vertices_m_.size()));
    double volume = 0.0;
    Vec3 first;
    Mat3 second = zero_matrix();
    for (const auto& t : triangles_) {
        const Vec3 a = vertices_m_[t[0]] - ref, b = vertices_m_[t[1]] - ref, c = vertices_m_[t[2]] - ref;
        const double det = dot(a, cross(b, c));
        volume += det / 6.0;
        first += (a + b + c) * (det / 24.0);
        const Vec3 s = a + b + c;
        Mat3 m = add(add(outer(a, a), outer(b, b)), outer(c, c));
        m = add(m, outer(s, s));
        second = add(second, m, det / 120.0);
    }
    volume_m3_ = volume;
    const Vec3 c = volume != 0.0 ? first * (1.0 / volume) : Vec3{};
    centroid_m_ = ref + c;
    covariance_ = add(second, outer(c, c), -volume);  // parallel-axis shift to the centroid
}

double ConvexPolyhedron::surface_area_m2() const
{
    double a = 0.0;
    for (const auto& t : triangles_)
        a += 0.5 * norm(cross(vertices_m_[t[1]] - vertices_m_[t[0]], vertices_m_[t[2]] - vertices_m_[t[0]]));
    return a;
}

Mat3 ConvexPolyhedron::inertia_about_centroid(double density) const
{
    const double trace = covariance_.m[0][0] + covariance_.m[1][1] + covariance_.m[2][2];
    Mat3 inertia;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) inertia.m[i][j] = density * ((i == j ? trace : 0.0) - covariance_.m[i][j]);
    return inertia;
}

PrincipalFrame ConvexPolyhedron::principal_frame(double density) const
{
    const Mat3 inertia = inertia_about_centroid(density);
    Eigen::Matrix3d m;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) m(i, j) = inertia.m[i][j];
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(m);
    Eigen::Matrix3d axes = solver.eigenvectors();
    if (axes.determinant() < 0.0) axes.col(2) = -axes.col(2);
    PrincipalFrame f;
    f.centre_m = centroid_m_;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) f.axes.m[i][j] = axes(i, j);
    f.moments_kg_m2 = {solver.eigenvalues()(0), solver.eigenvalues()(1), solver.eigenvalues()(2)};
    return f;
}

double ConvexPolyhedron::equivalent_diameter_m() const
{
    return std::cbrt(6.0 * volume_m3_ / M_PI);
}

double ConvexPolyhedron::support_m(const Vec3& d) const
{
    double best = -std::numeric_limits<double>::infinity();
    for (const Vec3& v : vertices_m_) best = std::max(best, dot(v, d));
    return best;
}

double ConvexPolyhedron::inner_radius_m() const
{
    double best = std::numeric_limits<double>::infinity();
    for (const auto& t : triangles_) {
        const Vec3 a = vertices_m_[t[0]];
        const Vec3 n = normalized(cross(vertices_m_[t[1]] - a, vertices_m_[t[2]] - a));
        best = std::min(best, dot(n, a - centroid_m_));
    }
    return best;
}

ConvexPolyhedron ConvexPolyhedron::transformed(const Mat3& rotation, const Vec3& translation) const
{
    ConvexPolyhedron p = *this;
    for (Vec3& v : p.vertices_m_) v = rotation * v + translation;
    p.compute_properties();
    return p;
}

ConvexPolyhedron ConvexPolyhedron::scaled(double factor) const
{
    ConvexPolyhedron p = *this;
    for (Vec3& v : p.vertices_m_) v = centroid_m_ + (v - centroid_m_) * factor;
    p.compute_properties();
    return p;
}

ConvexPolyhedron ConvexPolyhedron::in_principal_frame() const
{
    const PrincipalFrame f = principal_frame(1.0);
    const Mat3 to_body = f.axes.transposed();
    return transformed(to_body, to_body * (-centroid_m_));
}

ConvexPolyhedron ConvexPolyhedron::shrunk(double margin) const
{
    const auto& x = vertices_m_;
    std::vector<std::vector<std::pair<Vec3, double>>> planes(x.size());
    for (const auto& t : triangles_) {
        const Vec3 n = normalized(cross(x[t[1]] - x[t[0]], x[t[2]] - x[t[0]]));
        const double d = dot(n, x[t[0]]);
        for (const std::uint32_t v : t) {
            bool seen = false;  // coplanar triangles of one face count once
            for (const auto& [m, e] : planes[v]) seen = seen || dot(m, n) > 1.0 - 1e-9;
            if (!seen) planes[v].push_back({n, d});
        }
    }
    ConvexPolyhedron p = *this;
    for (std::size_t v = 0; v < x.size(); ++v) {
        // displacement minimising sum (n . (x + delta) - (d - margin))^2, lightly regularised so that a
        // vertex with fewer than three distinct faces moves the least distance
        Eigen::Matrix3d a = Eigen::Matrix3d::Identity() * 1e-12;
        Eigen::Vector3d b = Eigen::Vector3d::Zero();
        for (const auto& [n, d] : planes[v]) {
            const Eigen::Vector3d e(n.x, n.y, n.z);
            a += e * e.transpose();
            b += e * (d - margin - dot(n, x[v]));
        }
        const Eigen::Vector3d delta = a.ldlt().solve(b);
        p.vertices_m_[v] = x[v] + Vec3{delta(0), delta(1), delta(2)};
    }
    p.compute_properties();
    return p;
}

double ConvexPolyhedron::rounded_volume_m3(double r) const
{
    // each edge with the normals of its two triangles
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<Vec3>> edges;
    for (const auto& t : triangles_) {
        const Vec3 n = normalized(cross(vertices_m_[t[1]] - vertices_m_[t[0]], vertices_m_[t[2]] - vertices_m_[t[0]]));
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t a = t[static_cast<std::size_t>(k)], b = t[static_cast<std::size_t>((k + 1) % 3)];
            edges[{std::min(a, b), std::max(a, b)}].push_back(n);
        }
    }
    double edge_term = 0.0;
    for (const auto& [e, normals] : edges) {
        if (normals.size() != 2) continue;
        const double angle = std::acos(std::clamp(dot(normals[0], normals[1]), -1.0, 1.0));
        edge_term += norm(vertices_m_[e.first] - vertices_m_[e.second]) * angle;
    }
    return volume_m3_ + surface_area_m2() * r + 0.5 * r * r * edge_term + 4.0 / 3.0 * M_PI * r * r * r;
}

meshes::TriangleMesh ConvexPolyhedron::to_mesh() const
{
    return meshes::TriangleMesh(vertices_m_, triangles_, source_);
}

}  // namespace dipper::rigid
