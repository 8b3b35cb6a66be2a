/* tests/support/packed.h -- a scene loaded and packed at a given frame size, as the kernel modes'
 * tests take it (tests/unit/test_detailed.c, test_chip.c).
 *
 * Owns: loading and packing with the checks every such test makes (a scene from ../shared is
 * skipped, with the reason, where it is absent). Must not: hold a test's expectations.
 */
#ifndef SFSIM_TESTS_PACKED_H
#define SFSIM_TESTS_PACKED_H

#include "../../scenes/pack.h"
#include "../../scenes/scene.h"

/* path at w x h pixels and spp samples, into *s and *p (the default BVH). */
void packed_load(const char *path, int w, int h, int spp, Scene *s, PackedScene *p);
void packed_free(Scene *s, PackedScene *p);

#endif
