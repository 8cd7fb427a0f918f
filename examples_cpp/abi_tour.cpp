// abi_tour.cpp: every member of the C++ wrapper (bindings/cpp/fraccloth.hpp), once. Built by
// tests/cpp_binding.rs with -Wall -Wextra -Wshadow -Wconversion -Werror, run, and its output
// checked. Prints "tour ok" at the end; any failure throws fraccloth::Error (exit code 1).
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "fraccloth.hpp"

using fraccloth::Cloth;

static void require(bool ok, const char* what) {
    if (!ok) throw fraccloth::Error(FC_ERROR_INVALID_ARGUMENT, std::string("tour: ") + what);
}

int main(int argc, char** argv) try {
    const std::string dir = argc > 1 ? argv[1] : ".";
    require(fraccloth::version() == FC_VERSION, "version");

    FcClothDesc desc = fraccloth::preset_desc(FC_PRESET_UNDERWATER);
    require(desc.struct_size == sizeof(FcClothDesc), "struct_size");
    desc.width = 13;
    desc.height = 9;
    desc.spacing = 0.02f;
    Cloth cloth = Cloth::grid(desc);
    const std::size_t n = cloth.vertex_count();
    require(n == 117 && cloth.triangle_count() == 2 * 12 * 8, "counts");
    require(cloth.history_mode_count() == 0 && cloth.history_bytes_per_particle() == 0,
            "the underwater preset keeps no history");

    std::vector<uint32_t> top(13);
    for (uint32_t i = 0; i < 13; ++i) top[i] = i;
    cloth.set_pinned(top);
    std::vector<float> weights(n, 0.0f);
    for (uint32_t i = 0; i < 13; ++i) weights[i] = 1.0f;
    cloth.set_pin_weights(weights);
    cloth.pin_group(std::vector<uint32_t>{0, 12}, 1.0f);
    std::vector<float> rest = cloth.positions();
    std::vector<float> targets(rest.begin(), rest.begin() + 39);
    for (std::size_t i = 0; i < 13; ++i) targets[3 * i + 2] = 0.002f;
    cloth.set_pin_targets(top, targets);
    cloth.set_current(fraccloth::Vec3f{0.0f, 0.0f, 0.01f});
    cloth.set_current(std::array<double, 3>{0.0, 0.0, 0.02});
    cloth.set_threads(1);
    require(cloth.threads() == 1, "threads");

    const uint32_t sphere = cloth.add_sphere({0.0f, -0.3f, 0.05f}, 0.04f);
    cloth.set_sphere(sphere, {0.0f, -0.3f, 0.06f}, 0.04f, {0.0f, 0.0f, -0.01f});
    const uint32_t plane = cloth.add_plane({0.0f, -1.0f, 0.0f}, {0.0f, 1.0f, 0.0f});
    cloth.set_plane(plane, {0.0f, -1.1f, 0.0f}, {0.0f, 1.0f, 0.0f});
    const uint32_t capsule = cloth.add_capsule({-0.1f, -0.5f, 0.1f}, {0.1f, -0.5f, 0.1f}, 0.02f);
    cloth.set_capsule(capsule, {-0.1f, -0.5f, 0.12f}, {0.1f, -0.5f, 0.12f}, 0.02f);
    cloth.set_collider_friction(sphere, 0.3f);
    require(std::fabs(cloth.sphere(sphere).radius - 0.04f) < 1e-6f, "sphere");
    require(cloth.plane(plane).point[1] == -1.1f, "plane");
    require(cloth.capsule(capsule).b[2] == 0.12f, "capsule");
    // A mesh collider from the host's own buffers (one triangle under the cloth), moved once.
    std::vector<float> tri = {-1.0f, -0.8f, -1.0f, 1.0f, -0.8f, -1.0f, 0.0f, -0.8f, 1.0f};
    const std::vector<uint32_t> tri_indices = {0, 2, 1};
    const uint32_t mesh = cloth.add_mesh_collider(tri, tri_indices);
    tri[1] = tri[4] = tri[7] = -0.81f;
    cloth.set_mesh_collider(mesh, tri);
    cloth.set_collider_friction(mesh, 0.2f);
    cloth.set_collider_margin(mesh, 0.02f);
    require(cloth.collider_margin(mesh) == 0.02f, "mesh collider margin");
    require(std::fabs(cloth.collider_margin(sphere) - 0.01f) < 1e-6f, "the description's margin");
    require(cloth.mesh_collider_size(mesh)[1] == 1, "mesh collider size");
    bool thrown = false;
    try {
        cloth.set_mesh_collider(mesh, std::vector<float>(tri.begin(), tri.begin() + 6));
    } catch (const fraccloth::Error& e) {
        thrown = e.status() == FC_ERROR_INVALID_ARGUMENT;
    }
    require(thrown, "a mesh collider keeps its vertex count");

    cloth.step(1e-3);
    cloth.step_substeps(2e-3, 4);
    const std::vector<unsigned char> snapshot = cloth.save_snapshot();
    cloth.step(1e-3);
    const std::vector<float> after = cloth.positions();
    cloth.load_snapshot(snapshot);
    cloth.step(1e-3);
    require(cloth.positions() == after, "a snapshot resumes bit for bit");

    std::vector<float> out(3 * n);
    cloth.positions(out);
    std::vector<float> v = cloth.velocities();
    cloth.set_positions(out);
    cloth.set_velocities(v);
    std::vector<double> x64 = cloth.positions_f64(), v64 = cloth.velocities_f64();
    cloth.set_positions_f64(x64);
    cloth.set_velocities_f64(v64);
    const std::vector<float> normals = cloth.normals();
    const std::vector<uint32_t> triangles = cloth.triangles();
    require(normals.size() == 3 * n && triangles.size() == 3 * cloth.triangle_count(), "buffers");

    FcClothDesc now = cloth.desc();
    require(now.width == 13 && now.struct_size == sizeof(FcClothDesc), "desc");
    now.integrator = FC_INTEGRATOR_IMPLICIT_EULER;
    cloth.set_desc(now);
    cloth.set_solver(1e-7, 200);
    cloth.set_solver_accept_unconverged(false);
    cloth.step(1.0 / 60.0);
    const fraccloth::SolverStats stats = cloth.solver_stats();
    require(stats.iterations > 0 && stats.residual <= 1e-7, "solver stats");
    // The preset's automatic step chose the substeps of that call.
    const fraccloth::StepStats steps = cloth.step_stats();
    require(steps.substeps >= 1 && steps.estimate > 0.0, "step stats");
    // What the continuous collision check did: nothing left passing through.
    const fraccloth::CollisionStats hits = cloth.collision_stats();
    require(hits.unresolved == 0 && hits.passages >= hits.zone_steps, "collision stats");
    // Self-collision's step limit: this cloth has none, so nothing was split or slowed.
    const fraccloth::StepLimitStats limit = cloth.step_limit_stats();
    require(limit.split_substeps == 0 && limit.pieces == 0 && limit.slowed == 0, "step limit stats");
    cloth.remove_collider(capsule);

    cloth.write_obj(dir + "/tour.obj");
    {
        fraccloth::Cache cache(dir + "/tour.pc2", FC_CACHE_PC2, cloth, 1.0, 24.0, 2);
        cache.write_frame(cloth);
        cache.write_positions(cloth.positions());
        cache.close();
    }
    Cloth moved = std::move(cloth);
    require(moved.get() != nullptr && cloth.get() == nullptr, "move");
    try {
        moved.step(-1.0);
        require(false, "a negative step was accepted");
    } catch (const fraccloth::Error& e) {
        require(e.status() == FC_ERROR_INVALID_ARGUMENT, "status of a refused step");
    }
    std::printf("default width %u\n", fraccloth::default_desc().width);
    std::printf("tour ok\n");
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
}
