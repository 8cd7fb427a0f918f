/* mesh_collider.c: a character-like collider from an engine's own mesh.
 * The underwater towel (FC_PRESET_UNDERWATER, 31 x 21 at 2 cm) lies flat above a box mesh (the
 * host's vertex and index buffers, as a game engine or DCC holds them) that rises 5 cm and
 * turns over 2 s; each frame the host hands the box's new vertex positions to
 * fc_cloth_set_mesh_collider (a skinned mesh would do the same). Self-collision is on. Prints the
 * collider id, how many towel vertices ended inside the box (0), the lowest and highest towel
 * heights, and the statuses of calls with bad input. Usage: mesh_collider */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include "fraccloth.h"

/* Counter-clockwise seen from outside (the library also turns an inside-out closed mesh round). */
static const uint32_t box_indices[36] = {
    0, 1, 2, 0, 2, 3, /* bottom (-y) */ 4, 6, 5, 4, 7, 6, /* top (+y) */
    0, 5, 1, 0, 4, 5, /* -z */ 2, 7, 3, 2, 6, 7, /* +z */
    1, 6, 2, 1, 5, 6, /* +x */ 3, 4, 0, 3, 7, 4, /* -x */
};

/* The box's 8 corners: half-size 0.1 x 0.05 x 0.1 m, turned by `angle` about y, centre height `cy`. */
static void box_at(double angle, double cy, float *xyz) {
    const double hx = 0.1, hy = 0.05, hz = 0.1;
    const double c = cos(angle), s = sin(angle);
    for (int k = 0; k < 8; ++k) {
        const double x = (k == 1 || k == 2 || k == 5 || k == 6) ? hx : -hx;
        const double y = k >= 4 ? hy : -hy;
        const double z = (k == 2 || k == 3 || k == 6 || k == 7) ? hz : -hz;
        xyz[3 * k] = (float)(c * x + s * z);
        xyz[3 * k + 1] = (float)(cy + y);
        xyz[3 * k + 2] = (float)(-s * x + c * z);
    }
}

/* Whether p is inside the box at `angle`, centre height `cy` (the box's own frame). */
static int inside(const float *p, double angle, double cy) {
    const double c = cos(angle), s = sin(angle);
    const double x = c * p[0] - s * p[2], z = s * p[0] + c * p[2], y = p[1] - cy;
    return fabs(x) < 0.1 && fabs(y) < 0.05 && fabs(z) < 0.1;
}

int main(void) {
    FcClothDesc desc;
    if (fc_cloth_desc_preset(FC_PRESET_UNDERWATER, &desc) != FC_OK) return 1;
    desc.width = 31;
    desc.height = 21;
    desc.spacing = 0.02f;
    desc.self_collision_thickness = 0.005; /* the towel keeps 5 mm from itself */
    desc.self_collision_friction = 0.3;
    FcCloth *cloth = NULL;
    if (fc_cloth_create_grid(&desc, &cloth) != FC_OK) {
        fprintf(stderr, "create: %s\n", fc_last_error_message());
        return 1;
    }
    const size_t n = fc_cloth_vertex_count(cloth);
    float *xyz = malloc(3 * n * sizeof *xyz);
    if (!xyz) return 1;
    /* Lay the towel flat, 2 cm above the box's top, centred. */
    fc_cloth_get_positions(cloth, xyz, 3 * n);
    for (size_t i = 0; i < n; ++i) {
        const float x = xyz[3 * i] - 0.3f, y = xyz[3 * i + 1] + 0.2f;
        xyz[3 * i] = x;
        xyz[3 * i + 1] = 0.07f;
        xyz[3 * i + 2] = y;
    }
    if (fc_cloth_set_positions(cloth, xyz, 3 * n) != FC_OK) return 1;

    float box[24];
    box_at(0.0, 0.0, box);
    uint32_t id = 0;
    if (fc_cloth_add_mesh_collider(cloth, box, 8, box_indices, 36, NULL, &id) != FC_OK ||
        fc_cloth_set_collider_friction(cloth, id, 0.6) != FC_OK) {
        fprintf(stderr, "mesh collider: %s\n", fc_last_error_message());
        return 1;
    }
    /* The box keeps the cloth at the description's margin; a collider may have its own. */
    float margin = 0.0f;
    if (fc_cloth_set_collider_margin(cloth, id, 0.01f) != FC_OK ||
        fc_cloth_get_collider_margin(cloth, id, &margin) != FC_OK || margin != 0.01f) {
        fprintf(stderr, "collider margin: %s\n", fc_last_error_message());
        return 1;
    }
    size_t verts = 0, tris = 0;
    fc_cloth_get_mesh_collider(cloth, id, &verts, &tris);
    printf("collider %u vertices %zu triangles %zu\n", id, verts, tris);

    int worst_inside = 0;
    double angle = 0.0, cy = 0.0;
    for (int f = 1; f <= 60; ++f) {
        angle = 0.5 * f / 30.0;
        cy = 0.05 * f / 60.0;
        box_at(angle, cy, box);
        if (fc_cloth_set_mesh_collider(cloth, id, box, 8, NULL) != FC_OK ||
            fc_cloth_step(cloth, 1.0 / 30.0) != FC_OK) {
            fprintf(stderr, "frame %d: %s\n", f, fc_last_error_message());
            return 1;
        }
        fc_cloth_get_positions(cloth, xyz, 3 * n);
        int in = 0;
        for (size_t i = 0; i < n; ++i) in += inside(&xyz[3 * i], angle, cy);
        if (in > worst_inside) worst_inside = in;
    }
    float lo = 1e9f, hi = -1e9f;
    for (size_t i = 0; i < n; ++i) {
        if (xyz[3 * i + 1] < lo) lo = xyz[3 * i + 1];
        if (xyz[3 * i + 1] > hi) hi = xyz[3 * i + 1];
    }
    printf("inside %d\n", worst_inside);

    /* What the continuous check did: every output written, any may be NULL. */
    uint64_t zone_steps = UINT64_MAX, passages = UINT64_MAX, moved = UINT64_MAX;
    uint64_t unresolved = UINT64_MAX, carried = UINT64_MAX;
    FcStatus st = fc_cloth_get_collision_stats(cloth, &zone_steps, &passages, &moved, &unresolved, &carried);
    printf("collision_stats %d %llu %llu %llu %llu %llu\n", (int)st, (unsigned long long)zone_steps,
           (unsigned long long)passages, (unsigned long long)moved, (unsigned long long)unresolved,
           (unsigned long long)carried);
    printf("collision_stats_null %d %d\n",
           (int)fc_cloth_get_collision_stats(cloth, NULL, NULL, NULL, NULL, NULL),
           (int)fc_cloth_get_collision_stats(NULL, &zone_steps, NULL, NULL, NULL, NULL));
    printf("heights %.4f %.4f\n", lo, hi);

    /* Bad input: statuses, and nothing changes. */
    const uint32_t bad[3] = {0, 1, 99};
    uint32_t other = 0;
    printf("bad_index %d\n", (int)fc_cloth_add_mesh_collider(cloth, box, 8, bad, 3, NULL, &other));
    printf("bad_count %d\n", (int)fc_cloth_add_mesh_collider(cloth, box, 8, box_indices, 35, NULL, &other));
    printf("null_xyz %d\n", (int)fc_cloth_add_mesh_collider(cloth, NULL, 8, box_indices, 36, NULL, &other));
    printf("wrong_vertex_count %d\n", (int)fc_cloth_set_mesh_collider(cloth, id, box, 7, NULL));
    printf("no_such_id %d\n", (int)fc_cloth_set_mesh_collider(cloth, id + 5, box, 8, NULL));
    printf("removed %d\n", (int)fc_cloth_remove_collider(cloth, id));
    printf("after_remove %d\n", (int)fc_cloth_get_mesh_collider(cloth, id, &verts, &tris));
    /* A thickness of ten spacings: refused at create and when set on a cloth, which keeps
     * stepping with its own. */
    FcClothDesc thick = desc;
    thick.self_collision_thickness = 0.2;
    FcCloth *refused = NULL;
    printf("thick_create %d\n", (int)fc_cloth_create_grid(&thick, &refused));
    printf("thick_create_output %s\n", refused == NULL ? "none" : "written");
    printf("thick_set_desc %d\n", (int)fc_cloth_set_desc(cloth, &thick));
    printf("step_after %d\n", (int)fc_cloth_step(cloth, 1.0 / 30.0));
    /* A thickness in spacings: 0.3 of this 2 cm grid is 6 mm, read back in metres (the
     * relative field 0); ten spacings are refused as ten spacings in metres are. */
    FcClothDesc relative = desc;
    relative.self_collision_thickness = 0.0;
    relative.self_collision_relative = 0.3;
    FcCloth *by_spacing = NULL;
    relative.max_substep = 0.0; /* one substep a call, as a host at frame rate asks */
    printf("relative_create %d\n", (int)fc_cloth_create_grid(&relative, &by_spacing));
    FcClothDesc back = fc_cloth_desc_default();
    if (by_spacing && fc_cloth_get_desc(by_spacing, &back) == FC_OK)
        printf("relative_back %.6f %.1f\n", back.self_collision_thickness, back.self_collision_relative);
    /* Flung at 0.5 m/s: 17 mm in a 1/30 s substep, over five times the limit (half of 6 mm),
     * so the substep is taken in pieces (at least the 8 its speeds predict), and the
     * statistics count them. */
    size_t m = by_spacing ? fc_cloth_vertex_count(by_spacing) : 0;
    float *fling = calloc(3 * (m ? m : 1), sizeof(float));
    if (!fling) return 1;
    for (size_t i = 0; i < m; i++) fling[3 * i + 2] = 0.5f;
    uint32_t pieces = 0;
    if (by_spacing && fc_cloth_set_velocities(by_spacing, fling, 3 * m) == FC_OK &&
        fc_cloth_step(by_spacing, 1.0 / 30.0) == FC_OK &&
        fc_cloth_get_step_stats(by_spacing, &pieces, NULL, NULL) == FC_OK)
        printf("split_pieces %u\n", pieces);
    uint64_t split_substeps = 9, limit_pieces = 9, slowed = 9;
    FcStatus limit_status = fc_cloth_get_step_limit_stats(by_spacing, &split_substeps, &limit_pieces, &slowed);
    printf("limit_stats %d %llu %llu %llu\n", (int)limit_status, (unsigned long long)split_substeps,
           (unsigned long long)limit_pieces, (unsigned long long)slowed);
    printf("limit_stats_null %d %d\n", (int)fc_cloth_get_step_limit_stats(by_spacing, NULL, NULL, NULL),
           (int)fc_cloth_get_step_limit_stats(NULL, &split_substeps, NULL, NULL));
    free(fling);
    fc_cloth_destroy(by_spacing);
    relative.self_collision_relative = 10.0;
    by_spacing = NULL;
    printf("relative_thick %d\n", (int)fc_cloth_create_grid(&relative, &by_spacing));
    relative.self_collision_relative = -0.3;
    printf("relative_negative %d\n", (int)fc_cloth_create_grid(&relative, &by_spacing));
    printf("relative_output %s\n", by_spacing == NULL ? "none" : "written");
    free(xyz);
    fc_cloth_destroy(cloth);
    return 0;
}
