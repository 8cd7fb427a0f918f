/* icount.c: a host loop for instruction counts through the C ABI (docs/journal/2026-12-07-house.md).
 * cc -O2 -std=c99 -Iinclude scripts/icount.c -Ltarget/release -lfraccloth -lm -o target/icount
 * LD_LIBRARY_PATH=target/release valgrind --tool=callgrind target/icount PRESET WIDTH HEIGHT FRAMES [INTEGRATOR]
 * PRESET: 4 the underwater preset (frames of 1/60 s), -1 the library default (steps of 0.5 ms).
 * INTEGRATOR: an FcIntegrator value in place of the preset's (5: XPBD). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "fraccloth.h"
int main(int argc, char **argv) {
    if (argc < 5) return 2;
    int preset = atoi(argv[1]); uint32_t W = atoi(argv[2]), H = atoi(argv[3]); int frames = atoi(argv[4]);
    FcClothDesc desc = fc_cloth_desc_default();
    if (preset >= 0 && fc_cloth_desc_preset((FcPreset)preset, &desc) != FC_OK) return 2;
    desc.width = W; desc.height = H;
    if (argc > 5) desc.integrator = (uint32_t)atoi(argv[5]);
    FcCloth *cloth = NULL;
    if (fc_cloth_create_grid(&desc, &cloth) != FC_OK) { fprintf(stderr, "%s\n", fc_last_error_message()); return 1; }
    fc_cloth_set_threads(cloth, 1);
    size_t n = fc_cloth_vertex_count(cloth);
    float *xyz = malloc(3 * n * sizeof *xyz), *rest = malloc(3 * W * sizeof *rest), *target = malloc(3 * W * sizeof *target);
    uint32_t *top = malloc(W * sizeof *top);
    for (uint32_t i = 0; i < W; ++i) top[i] = i;
    fc_cloth_get_positions(cloth, xyz, 3 * n);
    for (uint32_t k = 0; k < 3 * W; ++k) rest[k] = xyz[k];
    fc_cloth_set_pinned(cloth, top, W);
    double dt = preset == 4 ? 1.0 / 60.0 : 5e-4;
    for (int f = 0; f < frames; ++f) {
        for (uint32_t i = 0; i < W; ++i) { target[3*i] = rest[3*i]; target[3*i+1] = rest[3*i+1]; target[3*i+2] = (float)(0.04 * sin(3.14159265 * (f + 1) * dt)); }
        if (fc_cloth_set_pin_targets(cloth, top, target, W) != FC_OK || fc_cloth_step(cloth, dt) != FC_OK) { fprintf(stderr, "%s\n", fc_last_error_message()); return 1; }
    }
    fc_cloth_get_positions(cloth, xyz, 3 * n);
    printf("%.9g %.9g\n", xyz[3*(n-1)+2], xyz[3*(n/2)+2]);
    fc_cloth_destroy(cloth);
    return 0;
}
