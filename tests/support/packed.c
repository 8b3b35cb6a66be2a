/* tests/support/packed.c -- see packed.h. */
#include "packed.h"

#include <criterion/criterion.h>

#include "shared.h"

void packed_load(const char *path, int w, int h, int spp, Scene *s, PackedScene *p)
{
    NEEDS_SCENE(path);
    char err[1024];
    cr_assert_eq(scene_load(path, s, err, sizeof err), 0, "%s: %s", path, err);
    s->render.width = w;
    s->render.height = h;
    s->render.spp = spp;
    BvhParams bp;
    bvh_default_params(&bp);
    cr_assert_eq(pack_scene(s, &bp, 0, p, err, sizeof err), 0, "%s", err);
}

void packed_free(Scene *s, PackedScene *p)
{
    pack_free(p);
    scene_free(s);
}
