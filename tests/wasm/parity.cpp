// The same cuts, printed bit for bit, from the native build and the WebAssembly build of mesh4d/
// (tests/wasm/run.sh compares the two): a sphere in uniform motion, spinning, accelerated and
// orbiting, each cut on the past cone in vertex mode and refined to a tolerance, with the Doppler
// factor and proper time of every output vertex (the orbit's through mesh4d/elliptic.h).
// Each number is printed as a C99 hexadecimal float (%a): exactly the double the build computed.
#include <cstdio>
#include <memory>
#include <vector>

#include "mesh4d/extrude.h"
#include "mesh4d/light_factors.h"
#include "mesh4d/slice.h"
#include "tests/test_meshes.h"

namespace {

using mesh4d::Vec3;

void print(const char* name, const mesh4d::ApparentMesh& m) {
    std::printf("%s: %zu vertices, %zu triangles\n", name, m.positions.size(), m.triangles.size());
    for (size_t i = 0; i < m.positions.size(); ++i) {
        const Vec3 p = m.absolutePosition(i);
        std::printf("v %a %a %a %a", p.x, p.y, p.z, m.absoluteTime(i));
        if (i < m.doppler.size()) std::printf(" %a", m.doppler[i]);
        if (i < m.proper_time.size()) std::printf(" %a", m.proper_time[i]);
        std::printf("\n");
    }
    for (const auto& t : m.triangles) std::printf("t %u %u %u\n", t[0], t[1], t[2]);
}

}  // namespace

int main() {
    // An icosphere: its vertices need only square roots, exact in every build (a torus's sines would
    // differ with the C library before any cut).
    const mesh4d::RestMesh sphere = testmesh::icosphere(1, 0.5);
    struct Case {
        const char* name;
        mesh4d::Motion motion;
    };
    std::vector<Case> cases;
    const mesh4d::Motion uniform = mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0, {-3, 0.4, -4}, {0.9, 0, 0});
    cases.push_back({"uniform", uniform});
    mesh4d::Motion spin = uniform;
    spin.angular_velocity = {0.3, 1.1, 0.2};
    cases.push_back({"spin", spin});
    mesh4d::Motion rocket = mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0, {-3, 0.4, -4}, {0.3, 0, 0});
    rocket.acceleration = {0.2, 0.05, 0};
    cases.push_back({"hyperbolic", rocket});
    mesh4d::Motion orbit = mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0, {1, 0.4, -4}, {0, 0, 0});
    mesh4d::Orbit o;
    o.center = {0, 0.4, -5};
    o.axis = {0.2, 1, 0.1};
    o.speed = 0.8;
    orbit.kinds.orbit = std::make_shared<const mesh4d::Orbit>(o);
    cases.push_back({"orbit", orbit});

    for (const Case& c : cases) {
        const mesh4d::World4D world = mesh4d::extrude(sphere, c.motion, -40, 40, false, false);
        mesh4d::ViewSurface view;
        view.kind = mesh4d::ViewKind::PastCone;
        view.t_c = 5.5;
        view.apex = {0, 0, 0};
        for (const double tolerance : {0.0, 1e-3}) {
            mesh4d::SliceSettings settings;
            settings.tolerance = tolerance;
            mesh4d::ApparentMesh m = mesh4d::sliceWorld(world, view, settings);
            mesh4d::addLightFactors(world, view, &m);
            std::printf("== %s, tolerance %g\n", c.name, tolerance);
            print(c.name, m);
        }
    }
    return 0;
}
