/* threads.c: a host steps four cloths on four of its own threads (as an engine's job system
 * would), each cloth told to use only the calling thread (fc_cloth_set_threads(cloth, 1)), and
 * checks that every cloth ends bit for bit where the same cloth stepped alone on the main
 * thread ends. Prints "identical 4 of 4". Build with -pthread. */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fraccloth.h"

#define CLOTHS 4
#define STEPS 400

struct job {
    FcCloth *cloth;
    int failed;
};

static FcCloth *make(int k) {
    FcClothDesc desc;
    if (fc_cloth_desc_preset(FC_PRESET_UNDERWATER, &desc) != FC_OK) return NULL;
    desc.width = 31;
    desc.height = 21;
    desc.spacing = 0.02f;
    desc.current[2] = 0.05 * k; /* a different current per cloth */
    FcCloth *cloth = NULL;
    if (fc_cloth_create_grid(&desc, &cloth) != FC_OK) return NULL;
    uint32_t top[31];
    for (uint32_t i = 0; i < 31; ++i) top[i] = i;
    if (fc_cloth_set_pinned(cloth, top, 31) != FC_OK || fc_cloth_set_threads(cloth, 1) != FC_OK) {
        fc_cloth_destroy(cloth);
        return NULL;
    }
    return cloth;
}

static void *run(void *arg) {
    struct job *job = arg;
    for (int s = 0; s < STEPS && !job->failed; ++s)
        if (fc_cloth_step(job->cloth, 5e-4) != FC_OK) job->failed = 1;
    return NULL;
}

int main(void) {
    struct job jobs[CLOTHS];
    pthread_t threads[CLOTHS];
    for (int k = 0; k < CLOTHS; ++k) {
        jobs[k].cloth = make(k);
        jobs[k].failed = jobs[k].cloth == NULL;
        if (jobs[k].failed) {
            fprintf(stderr, "create: %s\n", fc_last_error_message());
            return 1;
        }
    }
    for (int k = 0; k < CLOTHS; ++k)
        if (pthread_create(&threads[k], NULL, run, &jobs[k]) != 0) return 1;
    for (int k = 0; k < CLOTHS; ++k) pthread_join(threads[k], NULL);

    int identical = 0;
    size_t n = fc_cloth_vertex_count(jobs[0].cloth);
    float *a = malloc(3 * n * sizeof *a), *b = malloc(3 * n * sizeof *b);
    if (!a || !b) return 1;
    for (int k = 0; k < CLOTHS; ++k) {
        struct job alone = {make(k), 0};
        if (jobs[k].failed || alone.cloth == NULL) return 1;
        run(&alone);
        fc_cloth_get_positions(jobs[k].cloth, a, 3 * n);
        fc_cloth_get_positions(alone.cloth, b, 3 * n);
        identical += !alone.failed && memcmp(a, b, 3 * n * sizeof *a) == 0;
        fc_cloth_destroy(alone.cloth);
        fc_cloth_destroy(jobs[k].cloth);
    }
    printf("corner %.6f %.6f %.6f\n", a[3 * (n - 1)], a[3 * (n - 1) + 1], a[3 * (n - 1) + 2]);
    printf("identical %d of %d\n", identical, CLOTHS);
    free(a);
    free(b);
    return identical == CLOTHS ? 0 : 1;
}
