/* bad_input.c: every bad input returns the right status, a message, and leaves the cloth as it was. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fraccloth.h"

static int failures = 0, checks = 0;

static void expect(const char *what, FcStatus got, FcStatus want) {
    ++checks;
    if (got != want) {
        ++failures;
        printf("FAIL %s: got %d want %d (%s)\n", what, (int)got, (int)want, fc_last_error_message());
    } else if (want != FC_OK && fc_last_error_message()[0] == '\0') {
        ++failures;
        printf("FAIL %s: empty error message\n", what);
    }
}

int main(void) {
    FcClothDesc desc = fc_cloth_desc_default();
    desc.width = 4;
    desc.height = 3;
    FcCloth *cloth = NULL;
    expect("create", fc_cloth_create_grid(&desc, &cloth), FC_OK);
    size_t n = fc_cloth_vertex_count(cloth);
    float before[36], after[36], nan3[3] = {NAN, 0, 0};
    fc_cloth_get_positions(cloth, before, 3 * n);

    expect("NULL desc", fc_cloth_create_grid(NULL, &cloth), FC_ERROR_NULL_ARGUMENT);
    expect("NULL out", fc_cloth_create_grid(&desc, NULL), FC_ERROR_NULL_ARGUMENT);
    FcClothDesc small = desc;
    small.width = 1;
    FcCloth *none = NULL;
    expect("width 1", fc_cloth_create_grid(&small, &none), FC_ERROR_INVALID_ARGUMENT);
    small = desc;
    small.spacing = NAN;
    expect("NaN spacing", fc_cloth_create_grid(&small, &none), FC_ERROR_INVALID_ARGUMENT);
    small = desc;
    small.history_scheme = 99;
    expect("bad scheme", fc_cloth_create_grid(&small, &none), FC_ERROR_INVALID_ARGUMENT);
    if (none != NULL) { ++failures; printf("FAIL output written on error\n"); }

    expect("step NULL", fc_cloth_step(NULL, 0.001), FC_ERROR_NULL_ARGUMENT);
    expect("dt 0", fc_cloth_step(cloth, 0.0), FC_ERROR_INVALID_ARGUMENT);
    expect("dt < 0", fc_cloth_step(cloth, -1.0), FC_ERROR_INVALID_ARGUMENT);
    expect("dt NaN", fc_cloth_step(cloth, NAN), FC_ERROR_INVALID_ARGUMENT);
    expect("dt inf", fc_cloth_step(cloth, INFINITY), FC_ERROR_INVALID_ARGUMENT);
    uint32_t bad_index = 1000;
    expect("pin out of range", fc_cloth_set_pinned(cloth, &bad_index, 1), FC_ERROR_OUT_OF_RANGE);
    expect("pin NULL", fc_cloth_set_pinned(cloth, NULL, 2), FC_ERROR_NULL_ARGUMENT);
    uint32_t zero = 0;
    expect("target unpinned", fc_cloth_set_pin_targets(cloth, &zero, before, 1), FC_ERROR_INVALID_ARGUMENT);
    expect("positions short", fc_cloth_set_positions(cloth, before, 3 * n - 1), FC_ERROR_INVALID_ARGUMENT);
    expect("get short", fc_cloth_get_positions(cloth, after, 3 * n + 3), FC_ERROR_INVALID_ARGUMENT);
    float with_nan[36];
    memcpy(with_nan, before, sizeof before);
    with_nan[5] = NAN;
    expect("positions NaN", fc_cloth_set_positions(cloth, with_nan, 3 * n), FC_ERROR_INVALID_ARGUMENT);
    uint32_t id = 7;
    expect("sphere NaN", fc_cloth_add_sphere(cloth, nan3, 0.1f, NULL, &id), FC_ERROR_INVALID_ARGUMENT);
    float c[3] = {0, 0, 0};
    expect("sphere radius 0", fc_cloth_add_sphere(cloth, c, 0.0f, NULL, &id), FC_ERROR_INVALID_ARGUMENT);
    expect("remove missing", fc_cloth_remove_collider(cloth, 3), FC_ERROR_OUT_OF_RANGE);
    if (id != 7) { ++failures; printf("FAIL id written on error\n"); }
    if (fc_cloth_vertex_count(NULL) != 0) { ++failures; printf("FAIL count(NULL)\n"); }
    fc_cloth_destroy(NULL);

    fc_cloth_get_positions(cloth, after, 3 * n);
    ++checks;
    if (memcmp(before, after, sizeof(float) * 3 * n) != 0 || fc_cloth_time(cloth) != 0.0) {
        ++failures;
        printf("FAIL state changed by rejected calls\n");
    }
    fc_cloth_destroy(cloth);
    printf("%d checks, %d failures\n", checks, failures);
    return failures != 0;
}
