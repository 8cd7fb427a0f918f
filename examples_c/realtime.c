/* realtime.c: what a game engine does every frame, timed.
 * The underwater towel (FC_PRESET_UNDERWATER, 61 x 41, 1 cm) is stepped at 60 frames per second
 * while its top edge is swung; each frame the host moves the pins, steps 1/60 s once (the
 * preset's automatic step splits it into as few substeps as the cloth needs), and reads back
 * positions and normals as a renderer would; the index buffer is read once. Prints the mean and
 * worst time of a frame's cloth work against the 16.7 ms budget of a 60 Hz frame, and the mean
 * and largest substeps a frame took. Usage: realtime [frames] [integrator] (default 600 = 10 s; an
 * FcIntegrator value in place of the preset's, e.g. 1 for symplectic Euler, to compare). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "fraccloth.h"

static double now_ms(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec * 1e-6;
}

int main(int argc, char **argv) {
    const int frames = argc > 1 ? atoi(argv[1]) : 600;
    const double frame_dt = 1.0 / 60.0, budget_ms = 1000.0 / 60.0;
    FcClothDesc desc;
    if (frames <= 0 || fc_cloth_desc_preset(FC_PRESET_UNDERWATER, &desc) != FC_OK) return 2;
    if (argc > 2) desc.integrator = (uint32_t)atoi(argv[2]);
    /* desc.max_substep is FC_MAX_SUBSTEP_AUTO in the preset: one fc_cloth_step per frame. */
    FcCloth *cloth = NULL;
    if (fc_cloth_create_grid(&desc, &cloth) != FC_OK) {
        fprintf(stderr, "create: %s\n", fc_last_error_message());
        return 1;
    }
    /* The host's own thread steps this cloth: no other thread is used. */
    fc_cloth_set_threads(cloth, 1);
    const size_t n = fc_cloth_vertex_count(cloth), t = fc_cloth_triangle_count(cloth);
    const uint32_t w = desc.width;
    float *xyz = malloc(3 * n * sizeof *xyz), *normals = malloc(3 * n * sizeof *normals);
    float *rest = malloc(3 * w * sizeof *rest), *target = malloc(3 * w * sizeof *target);
    uint32_t *indices = malloc(3 * t * sizeof *indices), *top = malloc(w * sizeof *top);
    if (!xyz || !normals || !rest || !target || !indices || !top) return 1;
    /* The index buffer once: it never changes. */
    if (fc_cloth_get_triangles(cloth, indices, 3 * t) != FC_OK) return 1;
    for (uint32_t i = 0; i < w; ++i) top[i] = i;
    fc_cloth_get_positions(cloth, xyz, 3 * n);
    for (uint32_t k = 0; k < 3 * w; ++k) rest[k] = xyz[k];
    fc_cloth_set_pinned(cloth, top, w);

    double sum = 0.0, worst = 0.0, *times = malloc(frames * sizeof *times);
    if (!times) return 1;
    int over = 0;
    unsigned long substeps_sum = 0;
    uint32_t substeps_most = 0;
    for (int f = 0; f < frames; ++f) {
        const double start = now_ms();
        const double time = (f + 1) * frame_dt;
        for (uint32_t i = 0; i < w; ++i) { /* the top edge swings 8 cm along z at 0.5 Hz */
            target[3 * i] = rest[3 * i];
            target[3 * i + 1] = rest[3 * i + 1];
            target[3 * i + 2] = (float)(0.08 * sin(2.0 * 3.14159265358979 * 0.5 * time));
        }
        if (fc_cloth_set_pin_targets(cloth, top, target, w) != FC_OK ||
            fc_cloth_step(cloth, frame_dt) != FC_OK ||
            fc_cloth_get_positions(cloth, xyz, 3 * n) != FC_OK ||
            fc_cloth_get_normals(cloth, normals, 3 * n) != FC_OK) {
            fprintf(stderr, "frame %d: %s\n", f, fc_last_error_message());
            return 1;
        }
        const double ms = now_ms() - start;
        uint32_t substeps = 0;
        fc_cloth_get_step_stats(cloth, &substeps, NULL, NULL);
        substeps_sum += substeps;
        if (substeps > substeps_most) substeps_most = substeps;
        sum += ms;
        times[f] = ms;
        if (ms > worst) worst = ms;
        if (ms > budget_ms) ++over;
    }
    const float *c = &xyz[3 * (n - 1)], *nc = &normals[3 * (n - 1)];
    double depth = 0.0; /* how far the cloth was swung out of its plane, m */
    for (size_t k = 0; k < n; ++k) depth = fabs(xyz[3 * k + 2]) > depth ? fabs(xyz[3 * k + 2]) : depth;
    printf("cloth %zu vertices %zu triangles, %d frames of %.4f s\n", n, t, frames, frame_dt);
    for (int a = 1; a < frames; ++a) /* sort the frame times for the median */
        for (int b = a; b > 0 && times[b - 1] > times[b]; --b) { double x = times[b]; times[b] = times[b - 1]; times[b - 1] = x; }
    printf("frame_ms mean %.3f median %.3f worst %.3f budget %.3f over %d\n", sum / frames, times[frames / 2], worst, budget_ms, over);
    printf("substeps mean %.2f most %u\n", (double)substeps_sum / frames, (unsigned)substeps_most);
    printf("corner %.5f %.5f %.5f normal %.4f %.4f %.4f\n", c[0], c[1], c[2], nc[0], nc[1], nc[2]);
    printf("largest_z %.5f\n", depth);
    fc_cloth_destroy(cloth);
    free(times); free(xyz); free(normals); free(rest); free(target); free(indices); free(top);
    return 0;
}
