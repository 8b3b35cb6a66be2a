/* sim/ini.h -- the one INI reader of sfsim: machine configs (sim/config.c), scene.ini
 * (scenes/scene_file.c) and sweep files (sim/sweep.c) follow one set of rules, docs/ini.md.
 *
 * Owns: reading an INI file safely (regular files only, at most INIFILE_MAX_BYTES, lines of at
 * most INIFILE_MAX_LINE characters), splitting it into sections and keys through inih, and every
 * syntax rule: comments, [section] headers, key = value, indented continuation lines, a UTF-8 BOM,
 * a section or a key given twice. Messages name the file and the line, and are kept in one list
 * that the callers add their own messages to. Must not: know any section or key (each caller
 * checks them against its own table), exit, or print.
 *
 * The prefix is inifile_: inih owns ini_ and INI_.
 */
#ifndef SFSIM_INI_H
#define SFSIM_INI_H

#include <stddef.h>
#include <stdio.h>

/* The largest INI file read: far above any real config, scene or sweep file (the biggest sweep,
 * 100000 explicit points, is about 3 MB), small enough that /dev/zero or a wrong path to a disk
 * image fails at once. */
#define INIFILE_MAX_BYTES (16 * 1024 * 1024)
/* Characters of a line, its end (\n or \r\n) not counted: inih reads lines into a 200-byte buffer
 * (Debian's libinih is built with INI_MAX_LINE 200), which must also hold "\n" and the NUL. */
#define INIFILE_MAX_LINE 198
/* Characters of a section name: inih cuts longer ones silently (its MAX_SECTION is 50). */
#define INIFILE_MAX_SECTION 49
/* Messages kept per file; more are counted ("... and N more errors"). */
#define INIFILE_MAX_MESSAGES 200

typedef struct IniSection {
    const char *name;
    int line;  /* of its header */
    int nkeys; /* keys kept */
    int nbad;  /* its lines reported by the reader (syntax, repeated keys...) */
} IniSection;

typedef struct IniEntry {
    const char *section, *key;
    const char *value; /* without the blanks around it and its inline comment; continuation lines
                        * are appended after a '\n' each */
    int line;          /* of the key */
    int sec;           /* index of its section in IniFile.sections */
} IniEntry;

typedef struct IniMessage {
    int line; /* 0: about the whole file */
    char *text; /* "NAME:LINE: message" or "NAME: message" */
} IniMessage;

typedef struct IniOptions {
    int sections_repeat;           /* a section may appear again, its keys joining the first (machine
                                    * configs: a key is still given once); else a second header is an
                                    * error naming both lines */
    int bare_keys;                 /* messages name a key 'key', not 'section.key' (sweep files) */
    const char *const *repeatable; /* "section.key" names that may be given more than once,
                                    * NULL-terminated; NULL: none */
} IniOptions;

typedef struct IniFile {
    char *name;              /* the file as messages name it */
    IniSection *sections;    /* each name once, in file order */
    int nsections;
    IniEntry *entries;       /* every key kept, in file order */
    int nentries;
    IniMessage *messages;    /* the first INIFILE_MAX_MESSAGES; inifile_messages sorts them */
    int nmessages;
    int nerrors;             /* every message, kept or not */
    int oom;                 /* a message or an entry was lost for want of memory (counted) */
    /* private: the index of sections and keys */
    struct IniSlot *slots;
    size_t nslots, nused;
    IniOptions opt;
    int summarized;
} IniFile;

/* Read a whole INI file into memory (NUL-terminated, *len bytes); 0, or -1 with the reason in
 * err: "PATH: cannot open: ...", "PATH: is a directory, not a regular file", "PATH: not a regular
 * file (a character device)", "PATH: larger than 16 MiB". */
int inifile_read(const char *path, char **text, size_t *len, char *err, size_t errlen);

/* Parse text (len bytes) as the INI file `name` into f (which needs no set-up; free it with
 * inifile_free in any case). Returns the number of errors found. opt may be NULL. */
int inifile_parse(IniFile *f, const char *name, const char *text, size_t len, const IniOptions *opt);
/* The same from a file (inifile_read's rules; its failure is the one message) or a stream (at
 * most INIFILE_MAX_BYTES of it are read). */
int inifile_load(IniFile *f, const char *path, const IniOptions *opt);
int inifile_load_stream(IniFile *f, FILE *in, const char *name, const IniOptions *opt);

/* The first entry of key in section, the section called name; NULL when there is none. */
const IniEntry *inifile_get(const IniFile *f, const char *section, const char *key);
const IniSection *inifile_section(const IniFile *f, const char *name);

/* Add a message about line (0: the whole file), formatted "NAME:LINE: ..." like the reader's. */
void inifile_error(IniFile *f, int line, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
/* Every message in line order (the order found within a line), the last one saying how many
 * more there were when some were not kept. *n is the count of the array. */
const IniMessage *inifile_messages(IniFile *f, int *n);

void inifile_free(IniFile *f);

#endif
