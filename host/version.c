/* host/version.c -- the version and commit of this build (host/version.h). */
#include "version.h"

#include "version_gen.h" /* generated: $(BUILD)/gen/version_gen.h, scripts/version.sh */

const char *version_string(void)
{
    return SFSIM_VERSION_STRING;
}

const char *version_commit(void)
{
    return SFSIM_COMMIT_STRING;
}
