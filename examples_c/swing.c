/* swing.c: the paper's swing scene driven purely through the C ABI.
 * The top edge swings along z, z(t) = A sin(2 pi f t); the pins are moved every
 * step and the positions are written at 30 frames per second to a PC2 point cache.
 * Usage: swing OUT.pc2 [seconds] [fractional|regular] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fraccloth.h"

#define AMPLITUDE 0.08 /* m  (scenes::SWING_AMPLITUDE) */
#define FREQUENCY 0.5  /* Hz (scenes::SWING_FREQUENCY) */
#define DT 5e-4        /* s  (scenes::DEFAULT_DT) */
#define FPS 30

static void put_i32(FILE *f, int32_t v) {
    unsigned char b[4] = {(unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16), (unsigned char)(v >> 24)};
    fwrite(b, 1, 4, f);
}
static void put_f32(FILE *f, float v) {
    uint32_t u;
    memcpy(&u, &v, 4);
    put_i32(f, (int32_t)u);
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: %s OUT.pc2 [seconds] [fractional|regular]\n", argv[0]);
        return 2;
    }
    double seconds = argc > 2 ? atof(argv[2]) : 4.0;
    int regular = argc > 3 && strcmp(argv[3], "regular") == 0;

    FcClothDesc desc;
    if (fc_cloth_desc_preset(regular ? FC_PRESET_REGULAR_NORMAL : FC_PRESET_FRACTIONAL_PAPER, &desc) != FC_OK) return 1;
    FcCloth *cloth = NULL;
    if (fc_cloth_create_grid(&desc, &cloth) != FC_OK) {
        fprintf(stderr, "create: %s\n", fc_last_error_message());
        return 1;
    }
    size_t n = fc_cloth_vertex_count(cloth);
    uint32_t w = desc.width;
    float *xyz = malloc(3 * n * sizeof(float));
    float *rest = malloc(3 * w * sizeof(float));
    float *target = malloc(3 * w * sizeof(float));
    uint32_t *top = malloc(w * sizeof(uint32_t));
    if (!xyz || !rest || !target || !top) return 1;
    for (uint32_t i = 0; i < w; ++i) top[i] = i;
    fc_cloth_get_positions(cloth, xyz, 3 * n);
    memcpy(rest, xyz, 3 * w * sizeof(float));
    fc_cloth_set_pinned(cloth, top, w);

    FILE *f = fopen(argv[1], "wb");
    if (!f) {
        perror(argv[1]);
        return 1;
    }
    fwrite("POINTCACHE2", 1, 12, f); /* includes the terminating NUL */
    put_i32(f, 1);
    put_i32(f, (int32_t)n);
    put_f32(f, 0.0f);
    put_f32(f, 1.0f);
    long count_at = ftell(f);
    put_i32(f, 0);

    long steps = lround(seconds / DT);
    int32_t frames = 0;
    for (long s = 0; s <= steps; ++s) {
        if (s == lround(frames / (FPS * DT))) { /* frame k at t = k / FPS */
            fc_cloth_get_positions(cloth, xyz, 3 * n);
            for (size_t k = 0; k < 3 * n; ++k) put_f32(f, xyz[k]);
            ++frames;
        }
        if (s == steps) break;
        double t_end = (double)(s + 1) * DT;
        double z = AMPLITUDE * sin(2.0 * 3.14159265358979323846 * FREQUENCY * t_end);
        for (uint32_t i = 0; i < w; ++i) {
            target[3 * i] = rest[3 * i];
            target[3 * i + 1] = rest[3 * i + 1];
            target[3 * i + 2] = rest[3 * i + 2] + (float)z;
        }
        if (fc_cloth_set_pin_targets(cloth, top, target, w) != FC_OK || fc_cloth_step(cloth, DT) != FC_OK) {
            fprintf(stderr, "step %ld: %s\n", s, fc_last_error_message());
            return 1;
        }
    }
    fseek(f, count_at, SEEK_SET);
    put_i32(f, frames);
    fclose(f);
    size_t mid = n - w / 2 - 1;
    printf("frames %d vertices %zu steps %ld\n", frames, n, steps);
    printf("bottom-middle %.6f %.6f %.6f\n", xyz[3 * mid], xyz[3 * mid + 1], xyz[3 * mid + 2]);
    free(xyz);
    free(rest);
    free(target);
    free(top);
    fc_cloth_destroy(cloth);
    return 0;
}
