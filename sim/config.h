/* sim/config.h -- the machine configuration: the keys of sim/config.def as a struct, INI parsing
 * (sim/ini.h, the rules of docs/ini.md), --set overrides, checks, and the dump/markdown listings.
 *
 * Owns: every machine-config key's type, default, range and help. Must not: interpret keys
 * (the simulator's parts read the struct).
 */
#ifndef SFSIM_CONFIG_H
#define SFSIM_CONFIG_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "core.h"

typedef struct CfgMachine {
#define CFG_T_INT int32_t
#define CFG_T_I64 int64_t
#define CFG_T_FLOAT double
#define CFG_T_ENUM int32_t
#define CFG_KEY(sec, key, type, def, lo, hi, help) CFG_T_##type sec##_##key;
#include "config.def"
#undef CFG_KEY
} CfgMachine;

/* Errors are collected into a buffer, one per line; cfg_* return the number of errors. */
typedef struct CfgErrors {
    char *text;      /* malloc'ed, "\n"-separated; NULL when empty */
    size_t len;
    int count;
} CfgErrors;

void cfg_defaults(CfgMachine *cfg);
/* Read an INI file over cfg. Every problem is reported as "FILE:LINE: key 'sec.key': message"
 * (or "FILE:LINE: message" for syntax, "FILE: message" for a file that cannot be read: a
 * directory, a device or FIFO, more than 16 MiB), all of them, in line order. */
int cfg_load(CfgMachine *cfg, const char *path, CfgErrors *errs);
/* The same from an open stream (at most 16 MiB of it is read) or from text in memory; name is
 * used in the messages. */
int cfg_load_stream(CfgMachine *cfg, FILE *f, const char *name, CfgErrors *errs);
int cfg_load_text(CfgMachine *cfg, const char *text, size_t len, const char *name, CfgErrors *errs);
/* Apply "section.key=value"; errors name the option: "--set core.simd_width=999: ...". */
int cfg_set(CfgMachine *cfg, const char *assignment, CfgErrors *errs);
/* Cross-key consistency (e.g. a 4096-ray stream of 128-byte records must fit a ray buffer). */
int cfg_check(const CfgMachine *cfg, CfgErrors *errs);
void cfg_errors_free(CfgErrors *errs);

/* Memory sizes and width for the functional core. */
void cfg_core_params(const CfgMachine *cfg, CoreParams *p);

/* Values of the ENUM keys (index = stored value). */
enum { CFG_STREAM_MODE_STREAM = 0, CFG_STREAM_MODE_PACKET = 1 };
enum { CFG_STREAM_ORDER_RAY = 0, CFG_STREAM_ORDER_FIRST = 1 };
enum { CFG_WORKLOAD_PATH = 0, CFG_WORKLOAD_SPECULAR = 1, CFG_WORKLOAD_DIFFUSE = 2, CFG_WORKLOAD_PHONG = 3 };
enum { CFG_ACCEL_BVH = 0, CFG_ACCEL_KD = 1 };
enum { CFG_KERNEL_SCHEDULE_NONE = 0, CFG_KERNEL_SCHEDULE_LIST = 1 };
enum { CFG_CHIP_MEMORY_BUS = 0, CFG_CHIP_MEMORY_SHARED = 1 };
enum { CFG_L2_WRITE_BACK = 0, CFG_L2_WRITE_THROUGH = 1 };
/* kd.traversal; the kernel's KD_VARIANT takes these values (kernels/lib/kconst.inc: KD_STACK..KD_STREAM, generated). */
enum { CFG_KD_STACK = 0, CFG_KD_RESTART = 1, CFG_KD_PUSHDOWN = 2, CFG_KD_SHORTSTACK = 3, CFG_KD_PACKET = 4,
       CFG_KD_STREAM = 5, CFG_KD_TRAVERSALS };
/* The name of an ENUM key's value ("packet"), or NULL for other keys. */
const char *cfg_enum_name(const char *section, const char *key, int value);

/* Every key with type, default, range, help and the value in cfg. */
void cfg_dump(const CfgMachine *cfg, FILE *out);
/* docs/config.md. */
void cfg_markdown(FILE *out);
/* Every key with its value in cfg, as "section.key" members of the JSON object obj (report.json's
 * `config`): numbers for int, int64 and float keys, the value's name for enum keys. */
struct cJSON;
void cfg_json(const CfgMachine *cfg, struct cJSON *obj);

#endif
