// The built-in swing scene through the C++ wrapper: a 61 x 41 cloth, top row pinned and
// swung, a sphere and a plane below, 2 s at 0.5 ms; writes a PC2 and prints the last corner
// position and what the wrapper's error handling reports for a bad call.
// Usage: swing [out.pc2]
#include <cmath>
#include <cstdio>
#include <numeric>
#include <vector>

#include "fraccloth.hpp"

static constexpr double kPi = 3.14159265358979323846;

int main(int argc, char** argv) {
    try {
        FcClothDesc desc = fraccloth::default_desc();
        fraccloth::Cloth cloth = fraccloth::Cloth::grid(desc);
        std::vector<uint32_t> top(desc.width);
        std::iota(top.begin(), top.end(), 0u);
        cloth.set_pinned(top);
        std::vector<float> rest = cloth.positions();
        cloth.add_plane({0.0f, -0.6f, 0.0f}, {0.0f, 1.0f, 0.0f});
        uint32_t ball = cloth.add_sphere({0.0f, -0.3f, 0.2f}, 0.05f);
        cloth.set_collider_friction(ball, 0.3f);

        fraccloth::Cache cache(argc > 1 ? argv[1] : "swing_cpp.pc2", FC_CACHE_PC2, cloth, 1.0, 30.0);
        std::vector<float> targets(3 * top.size());
        const double dt = 5e-4;
        for (int k = 1; k <= 4000; ++k) {
            const double t = k * dt;
            for (size_t i = 0; i < top.size(); ++i) {
                targets[3 * i + 0] = rest[3 * top[i] + 0];
                targets[3 * i + 1] = rest[3 * top[i] + 1];
                targets[3 * i + 2] = rest[3 * top[i] + 2] + static_cast<float>(0.1 * std::sin(2.0 * kPi * 0.5 * t));
            }
            cloth.set_pin_targets(top, targets);
            cloth.step(dt);
            if (k % 100 == 0) {
                cache.write_frame(cloth);
            }
        }
        cache.close();
        std::vector<float> x = cloth.positions();
        const size_t corner = cloth.vertex_count() - desc.width;
        std::printf("corner %zu %.9g %.9g %.9g\n", corner, x[3 * corner], x[3 * corner + 1], x[3 * corner + 2]);

        // A bad call throws with the status and the message; the cloth is unchanged.
        try {
            cloth.step(-1.0);
            std::printf("no error\n");
            return 1;
        } catch (const fraccloth::Error& e) {
            std::printf("error %d %s\n", static_cast<int>(e.status()), e.what());
        }
        // The description reads back and changes between steps.
        FcClothDesc now = cloth.desc();
        now.bend_stiffness = 2.0 * now.bend_stiffness;
        cloth.set_desc(now);
        std::printf("desc %u %.3g\n", cloth.desc().width, cloth.desc().bend_stiffness);
        // Colliders read back.
        const uint32_t rod = cloth.add_capsule({0.0f, -0.5f, 0.2f}, {0.1f, -0.5f, 0.2f}, 0.02f);
        std::printf("capsule %.3g %.3g\n", static_cast<double>(cloth.capsule(rod).radius), static_cast<double>(cloth.capsule(rod).b[0]));
        cloth.remove_collider(rod);
        // The index buffer and normals a renderer draws with.
        std::printf("mesh %zu %zu\n", cloth.triangles().size(), cloth.normals().size());
        // The state in double precision round-trips exactly.
        std::vector<double> x64 = cloth.positions_f64();
        std::vector<double> v64 = cloth.velocities_f64();
        cloth.set_positions_f64(x64);
        cloth.set_velocities_f64(v64);
        std::printf("exact %d\n", static_cast<int>(cloth.positions_f64() == x64 && cloth.velocities_f64() == v64));
        // Moving the handle leaves the source empty; destroying it is harmless.
        fraccloth::Cloth moved = std::move(cloth);
        std::printf("moved %zu %zu\n", moved.vertex_count(), cloth.vertex_count());
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "failed: %s\n", e.what());
        return 1;
    }
}
