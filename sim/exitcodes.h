/* sim/exitcodes.h -- the EXIT_* codes of every command, from sim/exitcodes.def. */
#ifndef SFSIM_EXITCODES_H
#define SFSIM_EXITCODES_H

enum ExitCode {
#define EXITCODE(name, code, text) EXIT_##name = code,
#include "exitcodes.def"
#undef EXITCODE
};

#endif
