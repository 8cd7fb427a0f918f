/* stress.c: exercises every ABI call many times, with good and bad arguments, for the
 * memory checkers (AddressSanitizer + UndefinedBehaviorSanitizer, valgrind memcheck).
 * Creates and destroys cloths from grids and meshes, adds, moves and removes colliders,
 * pins, steps (also into instability), writes caches, saves and loads snapshots (also
 * corrupted ones). Prints "stress ok <checks>" and exits 0 when every status was as expected.
 * Usage: stress DIR [ROUNDS]   (a writable directory for the cache files; default 4 rounds) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fraccloth.h"

static int checks = 0;
static int failures = 0;

static void expect(FcStatus got, FcStatus want, const char *what) {
    ++checks;
    if (got != want) {
        ++failures;
        fprintf(stderr, "%s: got %d (%s), want %d\n", what, (int)got, fc_last_error_message(), (int)want);
    }
}

static FcCloth *grid(uint32_t w, uint32_t h, uint32_t scheme, uint32_t integrator) {
    FcClothDesc d = fc_cloth_desc_default();
    d.width = w;
    d.height = h;
    d.history_scheme = scheme;
    d.integrator = integrator;
    FcCloth *c = NULL;
    expect(fc_cloth_create_grid(&d, &c), FC_OK, "create grid");
    return c;
}

static void colliders_and_pins(FcCloth *c, uint32_t w) {
    uint32_t ids[3];
    float p[3] = {0.0f, -0.05f, 0.02f}, n[3] = {0.0f, 1.0f, 0.0f}, v[3] = {0.0f, 0.0f, -0.01f};
    float a[3] = {-0.1f, -0.03f, 0.03f}, b[3] = {0.1f, -0.03f, 0.03f}, zero[3] = {0, 0, 0};
    expect(fc_cloth_add_sphere(c, p, 0.01f, v, &ids[0]), FC_OK, "add sphere");
    expect(fc_cloth_add_plane(c, (float[3]){0.0f, -0.5f, 0.0f}, n, NULL, &ids[1]), FC_OK, "add plane");
    expect(fc_cloth_add_capsule(c, a, b, 0.01f, NULL, &ids[2]), FC_OK, "add capsule");
    expect(fc_cloth_set_collider_friction(c, ids[0], 0.5f), FC_OK, "friction");
    expect(fc_cloth_set_plane(c, ids[1], p, zero, NULL), FC_ERROR_INVALID_ARGUMENT, "zero normal");
    expect(fc_cloth_remove_collider(c, ids[1]), FC_OK, "remove plane");
    expect(fc_cloth_remove_collider(c, ids[1]), FC_ERROR_OUT_OF_RANGE, "remove twice");
    expect(fc_cloth_set_capsule(c, ids[2], a, b, 0.02f, v), FC_OK, "move capsule");
    uint32_t *top = malloc(w * sizeof *top);
    float *targets = malloc(3 * w * sizeof *targets);
    if (!top || !targets) exit(1);
    for (uint32_t i = 0; i < w; ++i) top[i] = i;
    expect(fc_cloth_set_pinned(c, top, w), FC_OK, "pin top");
    expect(fc_cloth_pin_group(c, top, 2, 0.5f), FC_OK, "soft pin group");
    expect(fc_cloth_get_positions(c, targets, 3 * w), FC_ERROR_INVALID_ARGUMENT, "short buffer");
    size_t nv = fc_cloth_vertex_count(c);
    float *xyz = malloc(3 * nv * sizeof *xyz);
    if (!xyz) exit(1);
    expect(fc_cloth_get_positions(c, xyz, 3 * nv), FC_OK, "positions");
    memcpy(targets, xyz, 3 * w * sizeof *targets);
    for (int k = 0; k < 50; ++k) {
        for (uint32_t i = 0; i < w; ++i) targets[3 * i + 2] = 0.01f * sinf(0.05f * (float)k);
        expect(fc_cloth_set_pin_targets(c, top, targets, w), FC_OK, "targets");
        expect(fc_cloth_step(c, 5e-4), FC_OK, "step");
    }
    free(xyz);
    free(top);
    free(targets);
}

static void snapshots(FcCloth *c) {
    size_t size = fc_cloth_snapshot_size(c);
    unsigned char *buf = malloc(size);
    if (!buf) exit(1);
    size_t written = 0;
    expect(fc_cloth_save_snapshot(c, buf, size - 1, &written), FC_ERROR_INVALID_ARGUMENT, "small buffer");
    expect(fc_cloth_save_snapshot(c, buf, size, &written), FC_OK, "save");
    expect(fc_cloth_step(c, 5e-4), FC_OK, "step after save");
    expect(fc_cloth_load_snapshot(c, buf, written), FC_OK, "load");
    for (size_t cut = 0; cut < written; cut += written / 7 + 1) {
        expect(fc_cloth_load_snapshot(c, buf, cut), FC_ERROR_INVALID_ARGUMENT, "truncated snapshot");
    }
    buf[written / 2] ^= 0x40;
    expect(fc_cloth_load_snapshot(c, buf, written), FC_ERROR_INVALID_ARGUMENT, "corrupted snapshot");
    free(buf);
}

static void caches(FcCloth *c, const char *dir) {
    char path[4096];
    const uint32_t formats[3] = {FC_CACHE_PC2, FC_CACHE_MDD, FC_CACHE_OBJ_SEQUENCE};
    const char *names[3] = {"s.pc2", "s.mdd", "s.obj"};
    for (int f = 0; f < 3; ++f) {
        snprintf(path, sizeof path, "%s/%s", dir, names[f]);
        FcCache *cache = NULL;
        expect(fc_cache_open(path, formats[f], c, 1.0, 24.0, 5, &cache), FC_OK, "cache open");
        for (int k = 0; k < 3; ++k) {
            expect(fc_cloth_step(c, 5e-4), FC_OK, "step");
            expect(fc_cache_write_frame(cache, c), FC_OK, "cache frame");
        }
        expect(fc_cache_close(cache), FC_OK, "cache close");
    }
    FcCache *cache = NULL;
    expect(fc_cache_open("/nonexistent-dir/x.pc2", FC_CACHE_PC2, c, 1.0, 24.0, 0, &cache), FC_ERROR_IO, "bad dir");
    expect(fc_cache_close(NULL), FC_OK, "close NULL");
    snprintf(path, sizeof path, "%s/rest.obj", dir);
    expect(fc_cloth_write_obj(c, path), FC_OK, "obj");
}

static void meshes(void) {
    float xyz[3 * 12];
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 4; ++i) {
            xyz[3 * (j * 4 + i)] = 0.02f * (float)i;
            xyz[3 * (j * 4 + i) + 1] = -0.02f * (float)j;
            xyz[3 * (j * 4 + i) + 2] = 0.0f;
        }
    uint32_t quads[4 * 6];
    int q = 0;
    for (uint32_t j = 0; j < 2; ++j)
        for (uint32_t i = 0; i < 3; ++i) {
            uint32_t a = j * 4 + i;
            quads[q++] = a;
            quads[q++] = a + 4;
            quads[q++] = a + 5;
            quads[q++] = a + 1;
        }
    FcClothDesc d = fc_cloth_desc_default();
    FcCloth *c = NULL;
    expect(fc_cloth_create_mesh(&d, xyz, 12, quads, 24, 4, &c), FC_OK, "quad mesh");
    expect(fc_cloth_step(c, 1e-3), FC_OK, "mesh step");
    fc_cloth_destroy(c);
    uint32_t bad[3] = {0, 1, 12};
    c = NULL;
    expect(fc_cloth_create_mesh(&d, xyz, 12, bad, 3, 3, &c), FC_ERROR_OUT_OF_RANGE, "bad index");
    uint32_t degenerate[3] = {0, 1, 2};
    expect(fc_cloth_create_mesh(&d, xyz, 12, degenerate, 3, 3, &c), FC_ERROR_INVALID_ARGUMENT, "degenerate");
    expect(fc_cloth_create_mesh(&d, xyz, 12, quads, 23, 4, &c), FC_ERROR_INVALID_ARGUMENT, "count");
    expect(fc_cloth_create_mesh(&d, NULL, 12, quads, 24, 4, &c), FC_ERROR_NULL_ARGUMENT, "NULL positions");
    if (c != NULL) ++failures;
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: %s DIR [ROUNDS]\n", argv[0]);
        return 2;
    }
    int rounds = argc > 2 ? atoi(argv[2]) : 4;
    for (int round = 0; round < rounds; ++round) {
        for (uint32_t scheme = 0; scheme < 4; ++scheme) {
            for (uint32_t integrator = 0; integrator < 3; ++integrator) {
                FcCloth *c = grid(12, 9, scheme, integrator);
                colliders_and_pins(c, 12);
                snapshots(c);
                fc_cloth_destroy(c);
            }
        }
        FcCloth *c = grid(10, 8, FC_HISTORY_SOE, FC_INTEGRATOR_SYMPLECTIC_EULER);
        caches(c, argv[1]);
        /* Into instability: very stiff springs and an explicit step far past its bound. */
        FcClothDesc stiff = fc_cloth_desc_default();
        stiff.width = 6;
        stiff.height = 5;
        stiff.stretch_stiffness = 1e5;
        FcCloth *s = NULL;
        expect(fc_cloth_create_grid(&stiff, &s), FC_OK, "stiff cloth");
        expect(fc_cloth_set_current(s, (float[3]){0.0f, 0.0f, 1.0f}), FC_OK, "current");
        FcStatus st = FC_OK;
        for (int k = 0; k < 20 && st == FC_OK; ++k) st = fc_cloth_step(s, 1e-2);
        expect(st, FC_ERROR_UNSTABLE, "explicit step past its bound");
        fc_cloth_destroy(s);
        expect(fc_cloth_step(c, -1.0), FC_ERROR_INVALID_ARGUMENT, "negative dt");
        expect(fc_cloth_step(c, NAN), FC_ERROR_INVALID_ARGUMENT, "NaN dt");
        expect(fc_cloth_step(NULL, 1e-3), FC_ERROR_NULL_ARGUMENT, "NULL cloth");
        fc_cloth_destroy(c);
        meshes();
        fc_cloth_destroy(NULL);
    }
    if (failures) {
        fprintf(stderr, "%d of %d checks failed\n", failures, checks);
        return 1;
    }
    printf("stress ok %d\n", checks);
    return 0;
}
