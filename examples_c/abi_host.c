/* A host that only knows the FcClothDesc of the header it was compiled against.
 * tests/old_host.rs compiles it twice, against include/fraccloth.h and against a copy whose
 * FcClothDesc lacks its last fields (an "old" header), and runs both on the same library:
 * the library reads and writes only the host's struct_size bytes and defaults the rest, so
 * both must give the same trajectory, and nothing past the host's struct is written.
 * `abi_host N` sets every byte of its description past the first N (the old host's
 * struct_size) to fc_cloth_desc_default()'s after taking the preset: what the library gives the
 * old host for the fields it lacks (a preset's own values there, such as the underwater
 * preset's bend_reference_spacing, reach only hosts that know the field). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fraccloth.h"

struct guarded {
  FcClothDesc desc;
  unsigned char canary[64];
};

static int fail(const char *what) {
  fprintf(stderr, "%s: %s\n", what, fc_last_error_message());
  return 1;
}

int main(int argc, char **argv) {
  struct guarded g;
  size_t i;
  memset(g.canary, 0xAB, sizeof g.canary);
  g.desc = fc_cloth_desc_default();
  if (g.desc.struct_size != sizeof(FcClothDesc)) return fail("fc_cloth_desc_default: struct_size");
  if (fc_cloth_desc_preset(FC_PRESET_UNDERWATER, &g.desc) != FC_OK) return fail("preset");
  g.desc.width = 21;
  g.desc.height = 15;
  g.desc.spacing = 0.02f;
  if (argc > 1) {
    size_t known = (size_t)strtoul(argv[1], NULL, 10);
    FcClothDesc defaults = fc_cloth_desc_default();
    if (known < sizeof(FcClothDesc))
      memcpy((char *)&g.desc + known, (const char *)&defaults + known, sizeof(FcClothDesc) - known);
  }

  FcCloth *cloth = NULL;
  if (fc_cloth_create_grid(&g.desc, &cloth) != FC_OK) return fail("create");
  uint32_t top[21];
  for (i = 0; i < 21; ++i) top[i] = (uint32_t)i;
  if (fc_cloth_set_pinned(cloth, top, 21) != FC_OK) return fail("pin");
  for (i = 0; i < 400; ++i)
    if (fc_cloth_step(cloth, 5e-4) != FC_OK) return fail("step");

  float xyz[21 * 15 * 3];
  if (fc_cloth_get_positions(cloth, xyz, sizeof xyz / sizeof xyz[0]) != FC_OK) return fail("positions");
  double sum = 0.0;
  for (i = 0; i < sizeof xyz / sizeof xyz[0]; ++i) sum += (double)xyz[i] * (double)(i % 7 + 1);

  /* Read back into the host's struct: exactly sizeof(FcClothDesc) bytes are written. */
  memset(&g.desc, 0, sizeof g.desc);
  if (fc_cloth_get_desc(cloth, &g.desc) != FC_OK) return fail("get_desc");
  if (g.desc.struct_size != sizeof(FcClothDesc) || g.desc.width != 21) return fail("get_desc fields");
  for (i = 0; i < sizeof g.canary; ++i)
    if (g.canary[i] != 0xAB) return fail("get_desc wrote past the host's struct");
  g.desc.form_drag *= 2.0;
  if (fc_cloth_set_desc(cloth, &g.desc) != FC_OK) return fail("set_desc");

  /* A size the library cannot know is refused with a message, not read. */
  g.desc.struct_size = (uint32_t)sizeof(FcClothDesc) + 4096u;
  FcCloth *other = NULL;
  if (fc_cloth_create_grid(&g.desc, &other) != FC_ERROR_INVALID_ARGUMENT || other != NULL)
    return fail("an oversized struct_size was accepted");
  if (strstr(fc_last_error_message(), "newer") == NULL) return fail("message");

  printf("struct_size %u\n", (unsigned)sizeof(FcClothDesc));
  printf("checksum %.17g\n", sum);
  fc_cloth_destroy(cloth);
  return 0;
}
