// fraccloth.hpp: header-only C++17 wrapper over the fraccloth C ABI (include/fraccloth.h).
//
// - fraccloth::Cloth and fraccloth::Cache own their handles (move-only, freed in the
//   destructor);
// - every failing call throws fraccloth::Error, which carries the FcStatus and the
//   library's message; a failed call leaves the cloth exactly as it was (the C ABI's rule);
// - buffers are passed as fraccloth::span (std::span with C++20, a minimal view before),
//   built implicitly from std::vector and std::array.
//
// Link against libfraccloth (pkg-config --libs fraccloth, or find_package(fraccloth) in
// CMake). Units are SI: m, kg, s.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#if __cplusplus >= 202002L && __has_include(<span>)
#include <span>
#endif

extern "C" {
#include "fraccloth.h"
}

namespace fraccloth {

#if __cplusplus >= 202002L && defined(__cpp_lib_span)
template <class T>
using span = std::span<T>;
#else
/// A pointer and a length: the part of std::span this wrapper needs, for C++17.
template <class T>
class span {
public:
    constexpr span() noexcept = default;
    constexpr span(T* data, std::size_t size) noexcept : data_(data), size_(size) {}
    template <class U, class A>
    span(std::vector<U, A>& v) noexcept : data_(v.data()), size_(v.size()) {}
    template <class U, class A>
    span(const std::vector<U, A>& v) noexcept : data_(v.data()), size_(v.size()) {}
    template <class U, std::size_t N>
    span(std::array<U, N>& a) noexcept : data_(a.data()), size_(N) {}
    template <class U, std::size_t N>
    span(const std::array<U, N>& a) noexcept : data_(a.data()), size_(N) {}
    constexpr T* data() const noexcept { return data_; }
    constexpr std::size_t size() const noexcept { return size_; }

private:
    T* data_ = nullptr;
    std::size_t size_ = 0;
};
#endif

/// A failed call: the status and the library's message.
class Error : public std::runtime_error {
public:
    Error(FcStatus status, const std::string& message)
        : std::runtime_error(std::string(fc_status_string(static_cast<int32_t>(status))) + ": " + message),
          status_(status) {}
    FcStatus status() const noexcept { return status_; }

private:
    FcStatus status_;
};

/// Throws Error unless `status` is FC_OK.
inline void check(FcStatus status) {
    if (status != FC_OK) {
        throw Error(status, fc_last_error_message());
    }
}

/// A 3-vector of floats (m, or m/s).
using Vec3f = std::array<float, 3>;

/// The library's version, `major * 1000000 + minor * 1000 + patch` (FC_VERSION of its header).
inline uint32_t version() noexcept { return fc_version(); }

/// Description with the library's defaults (a 61 x 41 grid of 1 cm, fractional model, SOE
/// history); `struct_size` is this header's `sizeof(FcClothDesc)`.
inline FcClothDesc default_desc() { return fc_cloth_desc_default(); }

/// Description of a preset (an FcPreset value).
inline FcClothDesc preset_desc(FcPreset preset) {
    FcClothDesc d = fc_cloth_desc_default();
    check(fc_cloth_desc_preset(static_cast<uint32_t>(preset), &d));
    return d;
}

/// What the last implicit solve did.
struct SolverStats {
    uint32_t iterations = 0;  ///< CG iterations
    double residual = 0.0;    ///< final relative residual
};

/// What the last step call did (`fc_cloth_get_step_stats`).
struct StepStats {
    uint32_t substeps = 0;  ///< substeps taken (the successful attempt's)
    uint32_t retries = 0;   ///< automatic step: attempts retried with twice the substeps
    double estimate = 0.0;  ///< automatic step: the substep estimate, s (0 with a fixed step)
};

/// What the continuous collision check did since the cloth was made
/// (`fc_cloth_get_collision_stats`).
struct CollisionStats {
    uint64_t zone_steps = 0;    ///< steps in which a self-collision pair would have passed
    uint64_t passages = 0;      ///< passages found
    uint64_t zone_moved = 0;    ///< free vertices moved with an impact zone, summed over steps
    uint64_t unresolved = 0;    ///< passages left (0: never through itself where pairs were listed)
    uint64_t mesh_carried = 0;  ///< cloth vertices a mesh collider carried, summed over steps
};

/// What self-collision's step limit did since the cloth was made
/// (`fc_cloth_get_step_limit_stats`).
struct StepLimitStats {
    uint64_t split_substeps = 0;  ///< substeps taken in pieces (no vertex past half the thickness)
    uint64_t pieces = 0;          ///< the pieces they were taken in
    uint64_t slowed = 0;          ///< free vertices slowed to the limit, split as far as it goes (not 0: motion held back)
};

/// One simulated cloth. Move-only; the handle is freed by the destructor.
class Cloth {
public:
    /// A grid cloth from `desc` (width x height vertices).
    static Cloth grid(const FcClothDesc& desc) {
        FcCloth* c = nullptr;
        check(fc_cloth_create_grid(&desc, &c));
        return Cloth(c);
    }

    /// A cloth from a mesh: xyz positions (3 floats per vertex) and face corner indices,
    /// `face_size` (3 or 4) per face.
    static Cloth mesh(const FcClothDesc& desc, span<const float> xyz, span<const uint32_t> indices,
                      uint32_t face_size) {
        FcCloth* c = nullptr;
        check(fc_cloth_create_mesh(&desc, xyz.data(), xyz.size() / 3, indices.data(), indices.size(),
                                   face_size, &c));
        return Cloth(c);
    }

    Cloth(Cloth&& other) noexcept : handle_(std::exchange(other.handle_, nullptr)) {}
    Cloth& operator=(Cloth&& other) noexcept {
        if (this != &other) {
            fc_cloth_destroy(handle_);
            handle_ = std::exchange(other.handle_, nullptr);
        }
        return *this;
    }
    Cloth(const Cloth&) = delete;
    Cloth& operator=(const Cloth&) = delete;
    ~Cloth() { fc_cloth_destroy(handle_); }

    /// The C handle, for calls this wrapper does not cover.
    FcCloth* get() const noexcept { return handle_; }

    std::size_t vertex_count() const noexcept { return fc_cloth_vertex_count(handle_); }
    std::size_t triangle_count() const noexcept { return fc_cloth_triangle_count(handle_); }
    /// Simulated time, s.
    double time() const noexcept { return fc_cloth_time(handle_); }
    /// Exponential modes of the SOE history per particle (0 for other schemes).
    uint32_t history_mode_count() const noexcept { return fc_cloth_history_mode_count(handle_); }
    /// Bytes of history kept per particle now.
    std::size_t history_bytes_per_particle() const noexcept {
        return fc_cloth_history_bytes_per_particle(handle_);
    }

    /// Where steps run: 0 the shared pool (default), 1 the calling thread only, n >= 2 a pool of
    /// the cloth's own. The result is the same for each.
    void set_threads(uint32_t threads) { check(fc_cloth_set_threads(handle_, threads)); }
    uint32_t threads() const noexcept { return fc_cloth_get_threads(handle_); }

    /// The implicit solver's CG tolerance (relative residual) and iteration cap.
    void set_solver(double tolerance, uint32_t max_iterations) {
        check(fc_cloth_set_solver(handle_, tolerance, max_iterations));
    }
    SolverStats solver_stats() const {
        SolverStats s;
        check(fc_cloth_get_solver_stats(handle_, &s.iterations, &s.residual));
        return s;
    }
    /// What the last `step` or `step_substeps` did (substeps, the automatic step's retries and
    /// estimate).
    StepStats step_stats() const {
        StepStats s;
        check(fc_cloth_get_step_stats(handle_, &s.substeps, &s.retries, &s.estimate));
        return s;
    }
    CollisionStats collision_stats() const {
        CollisionStats s;
        check(fc_cloth_get_collision_stats(handle_, &s.zone_steps, &s.passages, &s.zone_moved,
                                           &s.unresolved, &s.mesh_carried));
        return s;
    }
    StepLimitStats step_limit_stats() const {
        StepLimitStats s;
        check(fc_cloth_get_step_limit_stats(handle_, &s.split_substeps, &s.pieces, &s.slowed));
        return s;
    }
    /// Accept (true) or refuse (false, the default) implicit steps whose solver did not converge.
    void set_solver_accept_unconverged(bool accept) {
        check(fc_cloth_set_solver_accept_unconverged(handle_, accept ? 1 : 0));
    }

    /// The cloth's whole state as a checked binary snapshot (restore with load_snapshot).
    std::vector<unsigned char> save_snapshot() const {
        std::vector<unsigned char> bytes(fc_cloth_snapshot_size(handle_));
        std::size_t written = 0;
        check(fc_cloth_save_snapshot(handle_, bytes.data(), bytes.size(), &written));
        bytes.resize(written);
        return bytes;
    }
    void load_snapshot(span<const unsigned char> bytes) {
        check(fc_cloth_load_snapshot(handle_, bytes.data(), bytes.size()));
    }

    void set_pinned(span<const uint32_t> indices) { check(fc_cloth_set_pinned(handle_, indices.data(), indices.size())); }
    void set_pin_weights(span<const float> weights) {
        check(fc_cloth_set_pin_weights(handle_, weights.data(), weights.size()));
    }
    void pin_group(span<const uint32_t> indices, float weight) {
        check(fc_cloth_pin_group(handle_, indices.data(), indices.size(), weight));
    }
    /// Targets: 3 floats per index.
    void set_pin_targets(span<const uint32_t> indices, span<const float> xyz) {
        if (xyz.size() != 3 * indices.size()) {
            throw Error(FC_ERROR_INVALID_ARGUMENT, "set_pin_targets needs 3 floats per index");
        }
        check(fc_cloth_set_pin_targets(handle_, indices.data(), xyz.data(), indices.size()));
    }
    /// The uniform water current, m/s, from the next step.
    void set_current(const Vec3f& current) { check(fc_cloth_set_current(handle_, current.data())); }
    /// The current in double precision, exactly as the description holds it.
    void set_current(const std::array<double, 3>& current) {
        check(fc_cloth_set_current_f64(handle_, current.data()));
    }

    void step(double dt) { check(fc_cloth_step(handle_, dt)); }
    void step_substeps(double dt, uint32_t substeps) { check(fc_cloth_step_substeps(handle_, dt, substeps)); }

    /// Positions as xyz floats (3 per vertex).
    std::vector<float> positions() const {
        std::vector<float> xyz(3 * vertex_count());
        check(fc_cloth_get_positions(handle_, xyz.data(), xyz.size()));
        return xyz;
    }
    void positions(span<float> out) const { check(fc_cloth_get_positions(handle_, out.data(), out.size())); }
    std::vector<float> velocities() const {
        std::vector<float> xyz(3 * vertex_count());
        check(fc_cloth_get_velocities(handle_, xyz.data(), xyz.size()));
        return xyz;
    }
    void set_positions(span<const float> xyz) { check(fc_cloth_set_positions(handle_, xyz.data(), xyz.size())); }
    void set_velocities(span<const float> xyz) { check(fc_cloth_set_velocities(handle_, xyz.data(), xyz.size())); }
    /// The description now; `set_desc` changes coefficients between steps (not the history).
    FcClothDesc desc() const {
        FcClothDesc d = fc_cloth_desc_default();
        check(fc_cloth_get_desc(handle_, &d));
        return d;
    }
    void set_desc(const FcClothDesc& d) { check(fc_cloth_set_desc(handle_, &d)); }
    /// The index buffer: three vertex indices per triangle, fixed for the cloth's life.
    std::vector<uint32_t> triangles() const {
        std::vector<uint32_t> idx(3 * fc_cloth_triangle_count(handle_));
        check(fc_cloth_get_triangles(handle_, idx.data(), idx.size()));
        return idx;
    }
    /// Unit vertex normals at the current positions, three floats per vertex.
    std::vector<float> normals() const {
        std::vector<float> xyz(3 * vertex_count());
        check(fc_cloth_get_normals(handle_, xyz.data(), xyz.size()));
        return xyz;
    }
    /// The state in double precision, exactly (undo stacks, replicas, references).
    std::vector<double> positions_f64() const {
        std::vector<double> xyz(3 * vertex_count());
        check(fc_cloth_get_positions_f64(handle_, xyz.data(), xyz.size()));
        return xyz;
    }
    std::vector<double> velocities_f64() const {
        std::vector<double> xyz(3 * vertex_count());
        check(fc_cloth_get_velocities_f64(handle_, xyz.data(), xyz.size()));
        return xyz;
    }
    void set_positions_f64(span<const double> xyz) { check(fc_cloth_set_positions_f64(handle_, xyz.data(), xyz.size())); }
    void set_velocities_f64(span<const double> xyz) { check(fc_cloth_set_velocities_f64(handle_, xyz.data(), xyz.size())); }

    /// Colliders; each returns its id. A null velocity means resting.
    uint32_t add_sphere(const Vec3f& center, float radius, const Vec3f& velocity = {}) {
        uint32_t id = 0;
        check(fc_cloth_add_sphere(handle_, center.data(), radius, velocity.data(), &id));
        return id;
    }
    void set_sphere(uint32_t id, const Vec3f& center, float radius, const Vec3f& velocity = {}) {
        check(fc_cloth_set_sphere(handle_, id, center.data(), radius, velocity.data()));
    }
    uint32_t add_plane(const Vec3f& point, const Vec3f& normal, const Vec3f& velocity = {}) {
        uint32_t id = 0;
        check(fc_cloth_add_plane(handle_, point.data(), normal.data(), velocity.data(), &id));
        return id;
    }
    void set_plane(uint32_t id, const Vec3f& point, const Vec3f& normal, const Vec3f& velocity = {}) {
        check(fc_cloth_set_plane(handle_, id, point.data(), normal.data(), velocity.data()));
    }
    uint32_t add_capsule(const Vec3f& a, const Vec3f& b, float radius, const Vec3f& velocity = {}) {
        uint32_t id = 0;
        check(fc_cloth_add_capsule(handle_, a.data(), b.data(), radius, velocity.data(), &id));
        return id;
    }
    void set_capsule(uint32_t id, const Vec3f& a, const Vec3f& b, float radius, const Vec3f& velocity = {}) {
        check(fc_cloth_set_capsule(handle_, id, a.data(), b.data(), radius, velocity.data()));
    }
    /// A triangle-mesh collider from the host's buffers: `xyz` 3 floats a vertex (m), `indices`
    /// 3 a triangle (counter-clockwise seen from outside on a closed mesh), `velocities` empty
    /// (from the motion between steps) or 3 floats a vertex (m/s). Returns its id.
    uint32_t add_mesh_collider(span<const float> xyz, span<const uint32_t> indices,
                               span<const float> velocities = {}) {
        if (xyz.size() % 3 != 0 || (velocities.size() && velocities.size() != xyz.size()))
            throw Error(FC_ERROR_INVALID_ARGUMENT, "add_mesh_collider needs 3 floats a vertex (and as many velocities)");
        uint32_t id = 0;
        check(fc_cloth_add_mesh_collider(handle_, xyz.data(), xyz.size() / 3, indices.data(), indices.size(),
                                         velocities.size() ? velocities.data() : nullptr, &id));
        return id;
    }
    /// New positions of mesh collider `id`'s vertices (once a frame for a skinned mesh).
    void set_mesh_collider(uint32_t id, span<const float> xyz, span<const float> velocities = {}) {
        if (xyz.size() % 3 != 0 || (velocities.size() && velocities.size() != xyz.size()))
            throw Error(FC_ERROR_INVALID_ARGUMENT, "set_mesh_collider needs 3 floats a vertex (and as many velocities)");
        check(fc_cloth_set_mesh_collider(handle_, id, xyz.data(), xyz.size() / 3,
                                         velocities.size() ? velocities.data() : nullptr));
    }
    /// (vertex count, triangle count) of mesh collider `id`.
    std::array<std::size_t, 2> mesh_collider_size(uint32_t id) const {
        std::array<std::size_t, 2> n{};
        check(fc_cloth_get_mesh_collider(handle_, id, &n[0], &n[1]));
        return n;
    }
    void set_collider_friction(uint32_t id, float friction) {
        check(fc_cloth_set_collider_friction(handle_, id, friction));
    }
    /// Collider `id`'s own margin, m (>= 0), instead of the description's collision_margin.
    void set_collider_margin(uint32_t id, float margin) {
        check(fc_cloth_set_collider_margin(handle_, id, margin));
    }
    /// Collider `id`'s margin, m: its own, or the description's collision_margin.
    float collider_margin(uint32_t id) const {
        float m = 0.0f;
        check(fc_cloth_get_collider_margin(handle_, id, &m));
        return m;
    }
    void remove_collider(uint32_t id) { check(fc_cloth_remove_collider(handle_, id)); }
    /// Colliders read back (m, m/s); throw with FC_ERROR_OUT_OF_RANGE for an id of another kind.
    struct Sphere { Vec3f center; float radius; };
    struct Plane { Vec3f point, normal, velocity; };
    struct Capsule { Vec3f a, b; float radius; Vec3f velocity; };
    Sphere sphere(uint32_t id) const {
        Sphere s{};
        check(fc_cloth_get_sphere(handle_, id, s.center.data(), &s.radius));
        return s;
    }
    Plane plane(uint32_t id) const {
        Plane p{};
        check(fc_cloth_get_plane(handle_, id, p.point.data(), p.normal.data(), p.velocity.data()));
        return p;
    }
    Capsule capsule(uint32_t id) const {
        Capsule c{};
        check(fc_cloth_get_capsule(handle_, id, c.a.data(), c.b.data(), &c.radius, c.velocity.data()));
        return c;
    }

    void write_obj(const std::string& path) const { check(fc_cloth_write_obj(handle_, path.c_str())); }

private:
    explicit Cloth(FcCloth* handle) noexcept : handle_(handle) {}
    FcCloth* handle_ = nullptr;
};

/// A point cache being written (PC2, MDD or an OBJ sequence). Move-only; `close()` completes
/// the file and reports errors; the destructor closes silently if `close()` was not called.
class Cache {
public:
    Cache(const std::string& path, FcCacheFormat format, const Cloth& cloth, double start_frame = 1.0,
          double frames_per_second = 24.0, uint32_t expected_frames = 0) {
        check(fc_cache_open(path.c_str(), static_cast<uint32_t>(format), cloth.get(), start_frame,
                            frames_per_second, expected_frames, &handle_));
    }
    Cache(Cache&& other) noexcept : handle_(std::exchange(other.handle_, nullptr)) {}
    Cache& operator=(Cache&& other) noexcept {
        if (this != &other) {
            fc_cache_close(handle_);
            handle_ = std::exchange(other.handle_, nullptr);
        }
        return *this;
    }
    Cache(const Cache&) = delete;
    Cache& operator=(const Cache&) = delete;
    ~Cache() { fc_cache_close(handle_); }

    /// Appends the cloth's current positions as the next frame.
    void write_frame(const Cloth& cloth) { check(fc_cache_write_frame(handle_, cloth.get())); }
    /// Appends a frame of positions the host gives (3 floats per vertex, m).
    void write_positions(span<const float> xyz) { check(fc_cache_write_positions(handle_, xyz.data(), xyz.size())); }
    /// Completes the file; throws if that fails. The handle is gone either way.
    void close() { check(fc_cache_close(std::exchange(handle_, nullptr))); }

private:
    FcCache* handle_ = nullptr;
};

}  // namespace fraccloth
