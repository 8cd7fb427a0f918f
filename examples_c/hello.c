/* hello.c: create a cloth, pin its top row, step one second, print a corner.
 * Build (after scripts/install.sh; see the README's "Building a C program"):
 *   cc -std=c99 examples_c/hello.c $(pkg-config --cflags --libs fraccloth) -lm */
#include <stdio.h>
#include <stdlib.h>
#include "fraccloth.h"

int main(void) {
    /* The same major version, and a library no older than this header. */
    if (fc_version() / 1000000 != FC_VERSION_MAJOR || fc_version() < FC_VERSION) {
        fprintf(stderr, "header %d needs a library of the same major version, not older; got %u\n",
                FC_VERSION, fc_version());
        return 1;
    }
    FcClothDesc desc = fc_cloth_desc_default(); /* the paper's fractional cloth, 61 x 41 */
    FcCloth *cloth = NULL;
    if (fc_cloth_create_grid(&desc, &cloth) != FC_OK) {
        fprintf(stderr, "create failed: %s\n", fc_last_error_message());
        return 1;
    }
    uint32_t top[1024];
    for (uint32_t i = 0; i < desc.width; ++i) top[i] = i; /* row 0: indices 0 .. width-1 */
    if (fc_cloth_set_pinned(cloth, top, desc.width) != FC_OK) return 1;

    const double dt = 5e-4;
    for (int s = 0; s < 2000; ++s) {
        FcStatus st = fc_cloth_step(cloth, dt);
        if (st != FC_OK) {
            fprintf(stderr, "step %d: %s\n", s, fc_last_error_message());
            return 1;
        }
    }
    size_t n = fc_cloth_vertex_count(cloth);
    float *xyz = malloc(3 * n * sizeof(float));
    if (!xyz || fc_cloth_get_positions(cloth, xyz, 3 * n) != FC_OK) return 1;
    size_t corner = n - desc.width; /* bottom-left: column 0, last row */
    printf("vertices %zu\n", n);
    printf("time %.6f\n", fc_cloth_time(cloth));
    printf("corner %zu %.9g %.9g %.9g\n", corner, xyz[3 * corner], xyz[3 * corner + 1], xyz[3 * corner + 2]);
    free(xyz);
    fc_cloth_destroy(cloth);
    return 0;
}
