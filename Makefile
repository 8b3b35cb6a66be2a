# sfsim -- build, test, run. `make run` and `make test` install missing Debian packages first
# (scripts/deps.sh), then re-enter make so pkg-config sees them.

# A parallel build by default, on every core (as `make -jN` would); an explicit -j wins.
NPROC   := $(shell nproc 2>/dev/null || echo 1)
# Only the top-level make sets it: a sub-make shares its parent's jobs (GNU make's jobserver).
ifeq ($(MAKELEVEL)$(filter -j% --jobserver%,$(MAKEFLAGS)),0)
MAKEFLAGS += -j$(NPROC)
endif

CC      ?= cc
CXX     ?= c++
CLANG   ?= clang
OPT     ?= -O2
WARN    := -Wall -Wextra -Werror -Wshadow -Wstrict-prototypes -Wmissing-prototypes
# Built for this host's instruction set (-march=native); `make PORTABLE=1` builds for the
# compiler's baseline target instead, for binaries that must run on other machines. Results are
# identical either way (docs/performance.md): ISO C/C++ mode and -ffp-contract=off forbid fusing
# a multiply and an add, nothing uses -ffast-math, so only the choice of host instructions
# changes; make test-portable checks a portable build against the same-outputs table.
PORTABLE ?=
ARCH    := $(if $(PORTABLE),,-march=native) -ffp-contract=off
CFLAGS  := -std=c11 $(OPT) $(ARCH) -g $(WARN) -D_GNU_SOURCE $(EXTRA_CFLAGS)
# Link-time optimization: the objects carry the compiler's intermediate code beside their machine
# code (-ffat-lto-objects), and bin/sfsim and the benches link with -flto, so the timing core's
# calls into the units (sim/machine/) inline across files (docs/performance.md); the tests and
# tools link the machine code as usual. `make LTO=0` turns it off; results are the same either way.
LTO     ?= 1
LTO_OBJ  := $(if $(filter 1,$(LTO)),-flto=auto -ffat-lto-objects)
LTO_LINK := $(if $(filter 1,$(LTO)),-flto=auto)
AR      := $(if $(filter 1,$(LTO)),gcc-ar,$(AR))
CXXWARN := -Wall -Wextra -Werror
CXXFLAGS := -std=c++17 $(OPT) $(ARCH) -g $(CXXWARN) $(EXTRA_CXXFLAGS)
# C++ appears only inside the shims that wrap C++ libraries (ARCHITECTURE.md Sec. 2).
GLTF    := $(shell pkg-config --libs tinygltf 2>/dev/null || echo -ltinygltf)
TINYOBJ := $(shell pkg-config --libs tinyobjloader 2>/dev/null || echo -ltinyobjloader)
OIIO    := $(shell pkg-config --libs OpenImageIO 2>/dev/null || echo -lOpenImageIO -lOpenImageIO_Util)
CJSON   := $(shell pkg-config --libs libcjson 2>/dev/null || echo -lcjson)
# The image writers (sim/img_write.c, sim/heatmap.c) are C on C libraries linked into bin/sfsim:
# OpenEXR's C core (OpenEXR 3.1 has no .pc of its own, so its name is picked out of OpenEXR's),
# libpng and FreeType, which load with zlib and brotli in about a millisecond (docs/install.md).
IMGW_CFLAGS := $(shell pkg-config --cflags OpenEXR libpng freetype2 2>/dev/null || \
                 echo -I/usr/include/OpenEXR -I/usr/include/libpng16 -I/usr/include/freetype2)
IMGW_LIBS := $(or $(filter -L% -lOpenEXRCore%,$(shell pkg-config --libs OpenEXR 2>/dev/null)),-lOpenEXRCore-3_1) \
             $(shell pkg-config --libs libpng freetype2 2>/dev/null || echo -lpng16 -lfreetype)
# OpenImageIO is not in LDLIBS: it only reads images now, and bin/sfsim loads it with dlopen
# inside the image library (IMGLIB below) when `sfsim compare` needs it; the test and tool
# binaries that read images link its objects and $(OIIO).
# GSL: sampled mode's numerics (sim/sampling.c: the t quantile, the fit's Cholesky solves).
GSL     := $(shell pkg-config --libs gsl 2>/dev/null || echo -lgsl -lgslcblas -lm)
LDLIBS  := $(GLTF) $(TINYOBJ) $(CJSON) $(IMGW_LIBS) $(GSL) -lstdc++ -lpthread -ldl -lm
INIH    := $(shell pkg-config --cflags --libs inih 2>/dev/null || echo -linih)
CRIT    := $(shell pkg-config --libs criterion 2>/dev/null || echo -lcriterion)
EMBREE  := -lembree3

BUILD   ?= build
BIN     ?= bin
# Objects depend on the flags they were compiled with: switching PORTABLE, LTO (or OPT) rebuilds.
FLAGS_STAMP := $(BUILD)/.flags
$(shell mkdir -p $(BUILD) && (echo '$(CC) $(CFLAGS) $(LTO_OBJ) | $(CXX) $(CXXFLAGS)' | cmp -s - $(FLAGS_STAMP) || \
        echo '$(CC) $(CFLAGS) $(LTO_OBJ) | $(CXX) $(CXXFLAGS)' > $(FLAGS_STAMP)))
SAN     := -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined

# The build's version and commit (host/version.c): build/gen/version_gen.h is rewritten only when
# scripts/version.sh prints something new (a new commit, a tree that became dirty or clean).
$(shell mkdir -p $(BUILD)/gen && bash scripts/version.sh | cmp -s - $(BUILD)/gen/version_gen.h || \
        bash scripts/version.sh > $(BUILD)/gen/version_gen.h)

# Library sources: everything but the programs' main files. host/ (files in and out, the
# version) serves both programs.
HOST_SRC := $(wildcard host/*.c)
ISA_SRC := isa/isa.c
ASM_SRC := $(filter-out asm/main_sfasm.c,$(wildcard asm/*.c))
SIM_SRC := $(filter-out sim/main.c,$(wildcard sim/*.c sim/*/*.c))
SCN_SRC := $(wildcard scenes/*.c)
# The image library (sim/imgshim.h): the only code that links OpenImageIO, the image reader. Not
# in libsfsim.a: bin/sfsim loads it as IMGLIB with dlopen when it first reads an image
# (sim/imglib.c; `sfsim compare`), because OpenImageIO's ~265 shared libraries cost 120-250 ms at
# every start (docs/performance.md). Binaries that link libsfsim.a and read images link SHIM_OBJ
# instead (sim/imglib.c uses that copy).
SHIM_SRC := sim/img.cpp
CXX_SRC := $(filter-out $(SHIM_SRC),$(wildcard scenes/*.cpp sim/*.cpp))
LIB_SRC := $(HOST_SRC) $(ISA_SRC) $(ASM_SRC) $(SIM_SRC) $(SCN_SRC)
# An archive keeps members by file name only: two sources with one name in different folders
# (sim/a/x.c, sim/b/x.c) would silently replace each other in libsfsim.a.
LIB_NAMES := $(notdir $(basename $(LIB_SRC) $(CXX_SRC) $(SHIM_SRC)))
ifneq ($(words $(LIB_NAMES)),$(words $(sort $(LIB_NAMES))))
$(error two library sources share a file name: $(shell echo $(LIB_NAMES) | tr ' ' '\n' | sort | uniq -d))
endif
# Two Criterion binaries: tests/io (image files, Embree, scene files: they link OpenImageIO,
# Embree and tinygltf, whose ~270 shared libraries make every forked test process start slowly)
# and tests/unit (everything else, linked --as-needed so it starts fast). unit runs last.
TEST_SRC := $(wildcard tests/unit/*.c) tests/support/numerics.c tests/support/shared.c tests/support/files.c \
            tests/support/isa_expect.c tests/support/core_prog.c tests/support/scene_fixture.c tests/support/fixed_level.c \
            tests/support/asm_fixture.c tests/support/bvh_ref.c tests/support/packed.c tests/support/report_run.c
IO_TEST_SRC := $(wildcard tests/io/*.c) tests/support/xcheck.c tests/support/shared.c tests/support/files.c
LDAS    := -Wl,--as-needed

ASMLIB_OBJ = $(patsubst %.c,$(BUILD)/obj/%.o,$(HOST_SRC) $(ISA_SRC) $(ASM_SRC))
LIB_OBJ  = $(patsubst %.c,$(BUILD)/obj/%.o,$(LIB_SRC)) $(patsubst %.cpp,$(BUILD)/obj/%.o,$(CXX_SRC))
ASAN_OBJ = $(patsubst %.c,$(BUILD)/asan/%.o,$(LIB_SRC)) $(patsubst %.cpp,$(BUILD)/asan/%.o,$(CXX_SRC))
# The image library's objects: position-independent, every symbol hidden but its table.
SHIM_OBJ = $(patsubst %.cpp,$(BUILD)/shim/%.o,$(SHIM_SRC))
SHIM_ASAN_OBJ = $(patsubst %.cpp,$(BUILD)/asan/%.o,$(SHIM_SRC))
# Beside the binaries' folder, as installed (PREFIX/bin, PREFIX/lib/sfsim): lib/sfsim/ for bin/,
# build/portable/lib/sfsim/ for build/portable/bin/ (sim/imglib.h, docs/install.md).
LIBDIR  := $(patsubst ./%,%,$(dir $(BIN))lib)
IMGLIB  := $(LIBDIR)/sfsim/libsfsim-img.so

.PHONY: all deps install uninstall run test test-standalone test-asan test-unit test-hard test-slurm test-portable fuzz fuzz-run bench validation paper paper-chip docs check-docs clean run-built test-built check-outputs help

all: $(BIN)/sfasm $(BIN)/sfsim $(IMGLIB)

help:
	@echo "make run        install deps, build, run the example program"
	@echo "make test       install deps, build, run the whole test suite"
	@echo "make test-asan  the unit tests under AddressSanitizer + UBSan"
	@echo "make test-standalone  make run and make test in a clone with no ../shared beside it"
	@echo "make test-slurm the sweep's Slurm path on a real one-node Slurm started on localhost"
	@echo "make fuzz       build the libFuzzer targets, assembler and scene loader (clang);"
	@echo "                make fuzz-run FUZZ_SECONDS=600 runs each for that long"
	@echo "make bench      build and run the benchmarks in bench/ (core, functional and detailed speed, Embree,"
	@echo "                sampled mode's speed against error at 512 x 512 x 16, per-ray time against Embree,"
	@echo "                the chip's speed, sampled mode's error on chips of 16 and 64 cores: hours)"
	@echo "make validation the papers' experiments at reduced size into docs/validation-data.md (needs ../shared)"
	@echo "make paper      seed 001 Table 6 at the paper's scale in sampled mode, checked by one full detailed run"
	@echo "make paper-chip the paper's frame on chips of 1-256 cores with DDR4 and GDDR6, sampled (PAPER_CHIP_ARGS=--check: one detailed run)"
	@echo "                (about 90 min; PAPER_ARGS= skips the detailed run) into docs/validation-data.md"
	@echo "make docs       regenerate docs/config.md, docs/isa.md, docs/exit-codes.md, docs/report.md's statistics, the layout include and docs, the kernel constants, the shipped Cornell box"
	@echo "make check-outputs  the same-outputs table alone (tests/outputs/check.sh; part of make test)"
	@echo "make test-portable  the same table from a PORTABLE=1 build (the default builds for this host's CPU)"
	@echo "make install    install into PREFIX (default /usr/local; DESTDIR honoured): docs/install.md"
	@echo "make uninstall  remove what make install put into PREFIX"

# The same-outputs table (tests/outputs/outputs.tsv): cycles, instructions, image and report hashes.
check-outputs: all $(BUILD)/outputs_digest
	@bash tests/outputs/check.sh

# The same table from a build for the compiler's baseline target (PORTABLE=1) in $(BUILD)/portable:
# with make test's run of it on the default build for this host, the two builds give the same
# results (CI runs both).
test-portable: deps
	@$(MAKE) --no-print-directory PORTABLE=1 BUILD=$(BUILD)/portable BIN=$(BUILD)/portable/bin \
		$(BUILD)/portable/bin/sfsim $(BUILD)/portable/bin/sfasm $(BUILD)/portable/outputs_digest
	SFSIM_DATA_DIR=$(CURDIR) SFSIM=$(BUILD)/portable/bin/sfsim SFASM=$(BUILD)/portable/bin/sfasm \
		OUTPUTS_DIGEST=$(BUILD)/portable/outputs_digest bash tests/outputs/check.sh

deps:
	@bash scripts/deps.sh

run: deps
	@$(MAKE) --no-print-directory run-built

test: deps
	@$(MAKE) --no-print-directory test-built

$(BUILD)/obj/host/version.o $(BUILD)/asan/host/version.o: CFLAGS += -I$(BUILD)/gen

# Only the image writers see the image libraries' headers.
$(BUILD)/obj/sim/img_write.o $(BUILD)/obj/sim/heatmap.o $(BUILD)/asan/sim/img_write.o $(BUILD)/asan/sim/heatmap.o: \
	CFLAGS += $(IMGW_CFLAGS)

$(BUILD)/obj/%.o: %.c $(FLAGS_STAMP)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(LTO_OBJ) -MMD -MP -c $< -o $@

$(BUILD)/asan/%.o: %.c $(FLAGS_STAMP)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(SAN) -MMD -MP -c $< -o $@

$(BUILD)/obj/%.o: %.cpp $(FLAGS_STAMP)
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) -MMD -MP -c $< -o $@

$(BUILD)/asan/%.o: %.cpp $(FLAGS_STAMP)
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) $(SAN) -MMD -MP -c $< -o $@

$(BUILD)/shim/%.o: %.cpp $(FLAGS_STAMP)
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) -fPIC -fvisibility=hidden -MMD -MP -c $< -o $@

# The image library. -z defs: it needs nothing of the program; the
# version script keeps the template instances of OpenImageIO's headers out of its symbol table.
# Beside it, IMGLIB.deps: the order in which sim/imglib.c opens its dependencies
# (scripts/imglib_deps.sh).
$(IMGLIB): $(SHIM_OBJ) sim/imgshim.map scripts/imglib_deps.sh
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) -shared -Wl,-z,defs -Wl,--as-needed -Wl,--version-script=sim/imgshim.map $(SHIM_OBJ) -o $@.tmp $(OIIO)
	bash scripts/imglib_deps.sh $@.tmp > $@.deps
	mv $@.tmp $@

$(BUILD)/libsfasm.a: $(ASMLIB_OBJ)
	@mkdir -p $(dir $@)
	@rm -f $@
	$(AR) rcs $@ $^

$(BUILD)/libsfsim.a: $(LIB_OBJ)
	@mkdir -p $(dir $@)
	@rm -f $@
	$(AR) rcs $@ $^

$(BUILD)/libsfsim-asan.a: $(ASAN_OBJ)
	@mkdir -p $(dir $@)
	@rm -f $@
	$(AR) rcs $@ $^

$(BIN)/sfasm: $(BUILD)/obj/asm/main_sfasm.o $(BUILD)/libsfasm.a
	@mkdir -p $(BIN)
	$(CC) $(CFLAGS) $^ -o $@ -lm

# Its image library is built with it (order-only: not linked; sim/imglib.c loads it).
$(BIN)/sfsim: $(BUILD)/obj/sim/main.o $(BUILD)/libsfsim.a | $(IMGLIB)
	@mkdir -p $(BIN)
	$(CC) $(CFLAGS) $(LTO_LINK) $^ -o $@ $(INIH) $(LDLIBS)

# ---- tools and docs -------------------------------------------------------------------------
$(BUILD)/gen_isadoc: tools/gen_isadoc.c $(BUILD)/libsfasm.a
	$(CC) $(CFLAGS) $^ -o $@ -lm

$(BUILD)/gen_exitdoc: tools/gen_exitdoc.c sim/exitcodes.def sim/exitcodes.h
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) tools/gen_exitdoc.c -o $@

$(BUILD)/gen_layout: tools/gen_layout.c scenes/layout.def
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) tools/gen_layout.c -o $@

# docs/report.md's statistics tables from the registry (sim/stats.def).
$(BUILD)/gen_reportdoc: tools/gen_reportdoc.c $(BUILD)/libsfsim.a
	$(CC) $(CFLAGS) $^ -o $@ $(INIH) $(LDLIBS)

# The same-outputs table's digest of a run folder (tests/outputs/check.sh).
$(BUILD)/outputs_digest: tools/outputs_digest.c $(BUILD)/libsfsim.a $(SHIM_OBJ)
	$(CC) $(CFLAGS) $^ -o $@ $(INIH) $(LDLIBS) $(OIIO)

# The kernel's shared numbers (stages, workloads, kd variants, material and light kinds).
$(BUILD)/gen_kconst: tools/gen_kconst.c $(BUILD)/libsfsim.a
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(LDAS) $^ -o $@ $(INIH) $(LDLIBS)

# The shipped Cornell box, from the published measurements (scenes/cornell/cornell-box.gltf).
$(BUILD)/gen_cornell: tools/gen_cornell.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) tools/gen_cornell.c -o $@ $(CJSON) -lm

docs: $(BUILD)/gen_isadoc $(BUILD)/gen_layout $(BUILD)/gen_kconst $(BUILD)/gen_exitdoc $(BUILD)/gen_reportdoc $(BUILD)/gen_cornell $(BIN)/sfsim
	$(BIN)/sfsim config --markdown > docs/config.md.tmp && mv docs/config.md.tmp docs/config.md
	$(BUILD)/gen_cornell scenes/cornell
	$(BUILD)/gen_isadoc > docs/isa.md
	$(BUILD)/gen_exitdoc > docs/exit-codes.md
	$(BUILD)/gen_reportdoc docs/report.md > docs/report.md.tmp && mv docs/report.md.tmp docs/report.md
	$(BUILD)/gen_layout inc > kernels/lib/layout.inc
	$(BUILD)/gen_layout md > docs/scene-memory.md
	$(BUILD)/gen_kconst > kernels/lib/kconst.inc

# ---- tests ----------------------------------------------------------------------------------
$(BUILD)/tests/unit: $(TEST_SRC) $(BUILD)/libsfsim.a $(BUILD)/gen_isadoc $(BUILD)/gen_layout $(BUILD)/gen_kconst $(BUILD)/gen_exitdoc $(BUILD)/gen_reportdoc
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(LDAS) $(TEST_SRC) $(BUILD)/libsfsim.a -o $@ $(CRIT) $(INIH) $(LDLIBS)

$(BUILD)/tests/io: $(IO_TEST_SRC) $(BUILD)/libsfsim.a $(SHIM_OBJ)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(LDAS) $(IO_TEST_SRC) $(SHIM_OBJ) $(BUILD)/libsfsim.a -o $@ $(CRIT) $(EMBREE) $(INIH) $(LDLIBS) $(OIIO)

$(BUILD)/tests/unit-asan: $(TEST_SRC) $(BUILD)/libsfsim-asan.a $(BUILD)/gen_isadoc $(BUILD)/gen_layout $(BUILD)/gen_kconst $(BUILD)/gen_exitdoc $(BUILD)/gen_reportdoc
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(SAN) $(LDAS) $(TEST_SRC) $(BUILD)/libsfsim-asan.a -o $@ $(CRIT) $(INIH) $(LDLIBS)

$(BUILD)/tests/io-asan: $(IO_TEST_SRC) $(BUILD)/libsfsim-asan.a $(SHIM_ASAN_OBJ)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(SAN) $(LDAS) $(IO_TEST_SRC) $(SHIM_ASAN_OBJ) $(BUILD)/libsfsim-asan.a -o $@ $(CRIT) $(EMBREE) $(INIH) $(LDLIBS) $(OIIO)

HARD_TEST_SRC := $(wildcard tests/hard/*.c) tests/support/numerics.c tests/support/shared.c

$(BUILD)/tests/hard: $(HARD_TEST_SRC) tests/support/numerics.h tests/support/rng.h $(BUILD)/libsfsim.a $(SHIM_OBJ)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(LDAS) $(HARD_TEST_SRC) $(SHIM_OBJ) $(BUILD)/libsfsim.a -o $@ $(CRIT) $(INIH) $(LDLIBS) $(OIIO)

# The slow hard numerics cases (docs/numerics.md gives the run time).
test-hard: deps
	@$(MAKE) --no-print-directory all $(BUILD)/tests/hard
	@$(TEST_ENV) bash tests/run_criterion.sh $(BUILD)/tests/hard --jobs 2

# CLI tests first, Criterion last: its synthesis line closes the run.
TEST_ENV = SFSIM_BUILD=$(BUILD) SFSIM_GEN_ISADOC=$(BUILD)/gen_isadoc SFSIM_TEST_IMGLIB=$(IMGLIB)

# The tools the test suite does not run are still built (-Werror), so they cannot rot.
test-built: all $(BUILD)/tests/unit $(BUILD)/tests/io $(BUILD)/gen_cornell $(BUILD)/outputs_digest \
		$(BUILD)/validation $(BUILD)/paper $(BUILD)/paper_chip $(BUILD)/bench/speed_vs_error $(BUILD)/bench/per_ray \
		$(BUILD)/bench/chip_speed $(BUILD)/bench/chip_error
	@bash tests/outputs/check.sh
	@bash tests/cli/run.sh
	@bash tests/cli/sweep.sh
	@for t in $(sort $(wildcard tests/cli/cases/*.sh)); do bash $$t || exit 1; done
	@SFSIM_GEN_CORNELL=$(BUILD)/gen_cornell bash tests/cli/standalone.sh
	@$(TEST_ENV) bash tests/run_criterion.sh $(BUILD)/tests/io --jobs 2
	@$(TEST_ENV) bash tests/run_criterion.sh $(BUILD)/tests/unit --jobs 2

# A clone of the committed HEAD on its own (no ../shared): make run and make test pass, skipping
# with reasons what needs ../shared. CI runs it (a few minutes).
test-standalone: deps
	@bash tests/standalone_clone.sh

# The sweep's Slurm path against a real Slurm: installs slurmctld, slurmd, the client commands and
# munge (scripts/deps.sh slurm), starts them as a one-node cluster on localhost in a temporary
# folder, runs a 4-point sweep as an array job and checks it against a local run (tests/slurm/run.sh,
# docs/sweep.md). CI runs it; about 20 s once the packages are installed.
test-slurm: deps
	@bash scripts/deps.sh slurm
	@$(MAKE) --no-print-directory all
	@bash tests/slurm/run.sh

ASAN_ENV = ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp

test-asan: deps
	@$(MAKE) --no-print-directory $(BUILD)/tests/unit-asan $(BUILD)/tests/io-asan $(IMGLIB)
	@$(TEST_ENV) $(ASAN_ENV) bash tests/run_criterion.sh $(BUILD)/tests/io-asan --jobs 2
	@$(TEST_ENV) $(ASAN_ENV) bash tests/run_criterion.sh $(BUILD)/tests/unit-asan --jobs 2

# ---- fuzzing (clang + libFuzzer) -------------------------------------------------------------
FUZZ_SECONDS ?= 60
$(BUILD)/fuzz/fuzz_asm: tests/fuzz/fuzz_asm.c $(HOST_SRC) $(ISA_SRC) $(ASM_SRC)
	@mkdir -p $(dir $@)
	$(CLANG) -I$(BUILD)/gen -std=c11 -g -O1 -D_GNU_SOURCE -Wall -Wextra -Werror -fsanitize=fuzzer,address,undefined $^ -o $@ -lm

# The scene-loader fuzzer compiles tinygltf and stb_image into the shim (scenes/gltf_load.cpp
# acts on SFSIM_TINYGLTF_IMPLEMENTATION) so the sanitizers see inside them (the project's
# normal build links Debian's libtinygltf).
FUZZ_GLTF_OBJ := $(patsubst scenes/%.cpp,$(BUILD)/fuzz/%.o,$(wildcard scenes/gltf_*.cpp))
$(BUILD)/fuzz/gltf_%.o: scenes/gltf_%.cpp scenes/gltf_internal.hpp scenes/shim_util.hpp scenes/gltf.h scenes/scene.h
	@mkdir -p $(dir $@)
	$(CLANG)++ -std=c++17 -g -O1 -fsanitize=fuzzer-no-link,address,undefined -isystem /usr/include/stb \
	    -DSFSIM_TINYGLTF_IMPLEMENTATION -c $< -o $@

# The OBJ shim likewise compiles tinyobjloader in (SFSIM_TINYOBJ_IMPLEMENTATION); its image decoder is
# tinygltf's, in the glTF objects.
$(BUILD)/fuzz/obj_load.o: scenes/obj_load.cpp scenes/obj.h scenes/shim_util.hpp scenes/scene.h
	@mkdir -p $(dir $@)
	$(CLANG)++ -std=c++17 -g -O1 -fsanitize=fuzzer-no-link,address,undefined -DSFSIM_TINYOBJ_IMPLEMENTATION \
	    -c $< -o $@

$(BUILD)/fuzz/fuzz_scene: tests/fuzz/fuzz_scene.c scenes/scene.c scenes/scene_file.c sim/ini.c host/infile.c $(FUZZ_GLTF_OBJ) \
		$(BUILD)/fuzz/obj_load.o
	@mkdir -p $(dir $@)
	$(CLANG)++ -x c -std=c11 -g -O1 -D_GNU_SOURCE -Wall -Wextra -Werror -fsanitize=fuzzer,address,undefined \
	    $(filter %.c,$^) -x none $(filter %.o,$^) -o $@ -linih -lcjson -lm

$(BUILD)/fuzz/fuzz_rays: tests/fuzz/fuzz_rays.c sim/raybatch.c host/outfile.c host/infile.c sim/util.c
	@mkdir -p $(dir $@)
	$(CLANG) -std=c11 -g -O1 -D_GNU_SOURCE -Wall -Wextra -Werror -fsanitize=fuzzer,address,undefined $^ -o $@ -lm

# The timing model of one core: what fuzz_config builds from the config it fuzzes.
TM_SRC := sim/timing.c sim/event.c $(wildcard sim/machine/*.c sim/timing/*.c) sim/mem/cache.c sim/mem/bus.c
# ... and the chip's shared memory, whose keys the config's check asks about (sim/chip/chip.h)
TM_SRC += sim/chip/chip.c sim/mem/dram.c sim/mem/dram_sched.c sim/mem/dram_level.c sim/mem/l2.c sim/mem/noc.c sim/mem/monitor.c

$(BUILD)/fuzz/fuzz_config: tests/fuzz/fuzz_config.c sim/config.c sim/ini.c host/infile.c $(TM_SRC) isa/isa.c
	@mkdir -p $(dir $@)
	$(CLANG) -std=c11 -g -O1 -D_GNU_SOURCE -Wall -Wextra -Werror -fsanitize=fuzzer,address,undefined $^ -o $@ $(INIH) $(CJSON) -lm

fuzz: $(BUILD)/fuzz/fuzz_asm $(BUILD)/fuzz/fuzz_scene $(BUILD)/fuzz/fuzz_rays $(BUILD)/fuzz/fuzz_config

fuzz-run: fuzz
	@mkdir -p $(BUILD)/fuzz/corpus $(BUILD)/fuzz/scene_corpus
	$(BUILD)/fuzz/fuzz_asm -max_total_time=$(FUZZ_SECONDS) -max_len=4096 $(BUILD)/fuzz/corpus tests/fuzz/seeds
	$(BUILD)/fuzz/fuzz_scene -max_total_time=$(FUZZ_SECONDS) -max_len=65536 -timeout=30 $(BUILD)/fuzz/scene_corpus tests/scenes tests/scenes/obj
	@mkdir -p $(BUILD)/fuzz/ray_corpus
	$(BUILD)/fuzz/fuzz_rays -max_total_time=$(FUZZ_SECONDS) -max_len=8192 $(BUILD)/fuzz/ray_corpus tests/fuzz/ray_seeds
	@mkdir -p $(BUILD)/fuzz/config_corpus
	$(BUILD)/fuzz/fuzz_config -max_total_time=$(FUZZ_SECONDS) -max_len=4096 $(BUILD)/fuzz/config_corpus tests/fuzz/config_seeds

# ---- benchmarks -----------------------------------------------------------------------------
$(BUILD)/bench/core_speed: bench/core_speed.c $(BUILD)/libsfsim.a $(SHIM_OBJ)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(LTO_LINK) $^ -o $@ $(INIH) $(LDLIBS) $(OIIO)

$(BUILD)/bench/sched_speed: bench/sched_speed.c $(BUILD)/libsfasm.a
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $^ -o $@ -lm

$(BUILD)/bench/embree_xcheck: bench/embree_xcheck.c tests/support/xcheck.c tests/support/shared.c $(BUILD)/libsfsim.a $(SHIM_OBJ)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(LTO_LINK) $^ -o $@ $(EMBREE) $(INIH) $(LDLIBS) $(OIIO)

$(BUILD)/bench/per_ray: bench/per_ray.c tests/support/xcheck.c tests/support/shared.c $(BUILD)/libsfsim.a $(SHIM_OBJ)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(LTO_LINK) $^ -o $@ $(EMBREE) $(INIH) $(LDLIBS) $(OIIO)

$(BUILD)/bench/functional_speed: bench/functional_speed.c tests/support/shared.c $(BUILD)/libsfsim.a $(SHIM_OBJ)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(LTO_LINK) $^ -o $@ $(INIH) $(LDLIBS) $(OIIO)

$(BUILD)/bench/detailed_speed: bench/detailed_speed.c tests/support/shared.c $(BUILD)/libsfsim.a $(SHIM_OBJ)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(LTO_LINK) $^ -o $@ $(INIH) $(LDLIBS) $(OIIO)

$(BUILD)/bench/chip_speed: bench/chip_speed.c tests/support/shared.c $(BUILD)/libsfsim.a $(SHIM_OBJ)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(LTO_LINK) $^ -o $@ $(INIH) $(LDLIBS) $(OIIO)

$(BUILD)/bench/chip_error: bench/chip_error.c tests/support/shared.c $(BUILD)/libsfsim.a $(SHIM_OBJ)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(LTO_LINK) $^ -o $@ $(INIH) $(LDLIBS) $(OIIO)

$(BUILD)/bench/speed_vs_error: bench/speed_vs_error.c tests/support/shared.c $(BUILD)/libsfsim.a $(SHIM_OBJ)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(LTO_LINK) $^ -o $@ $(INIH) $(LDLIBS) $(OIIO)

$(BUILD)/validation: tools/validation.c $(BUILD)/libsfsim.a $(SHIM_OBJ)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $^ -o $@ $(INIH) $(LDLIBS) $(OIIO)

# The utilization experiments of docs/validation.md (several minutes on 2 cores).
$(BUILD)/paper: tools/paper.c $(BUILD)/libsfsim.a $(SHIM_OBJ)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $^ -o $@ $(INIH) $(LDLIBS) $(OIIO)

$(BUILD)/paper_chip: tools/paper_chip.c $(BUILD)/libsfsim.a $(SHIM_OBJ)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $^ -o $@ $(INIH) $(LDLIBS) $(OIIO)

# The utilization experiments of docs/validation.md (several minutes on 2 cores). The section
# `make paper` wrote is kept.
validation: deps
	@$(MAKE) --no-print-directory $(BUILD)/validation
	sed -n '/<!-- make paper: begin -->/,/<!-- make paper: end -->/p' docs/validation-data.md > $(BUILD)/paper-section.md
	$(BUILD)/validation > $(BUILD)/validation-data.md
	cat $(BUILD)/validation-data.md $(BUILD)/paper-section.md > docs/validation-data.md

# Seed 001 Table 6 at the paper's scale in sampled mode, with one full detailed run to check it
# (tools/paper.c: about 90 minutes on 2 cores, most of it the detailed run); its section of
# docs/validation-data.md is replaced. PAPER_ARGS= (empty) skips the detailed run.
PAPER_ARGS ?= --check
paper: deps
	@$(MAKE) --no-print-directory all $(BUILD)/paper
	$(BUILD)/paper $(PAPER_ARGS) > $(BUILD)/paper-section.md
	sed '/<!-- make paper: begin -->/,/<!-- make paper: end -->/d' docs/validation-data.md > $(BUILD)/validation-data.md
	cat $(BUILD)/validation-data.md $(BUILD)/paper-section.md > docs/validation-data.md

# The paper's frame on chips of K = 1, 4, 16, 64, 256 cores with two memories, each point sampled
# at 1 % (tools/paper_chip.c: under 30 minutes on 2 cores); --check adds one full detailed run of
# K = 16 with DDR4 (about 95 minutes more). Its section of docs/validation-data.md is replaced and
# docs/img/paper-chip-fps.png redrawn with gnuplot.
PAPER_CHIP_ARGS ?=
paper-chip: deps
	@$(MAKE) --no-print-directory all $(BUILD)/paper_chip
	$(BUILD)/paper_chip $(PAPER_CHIP_ARGS) $(BUILD)/paper-chip.dat > $(BUILD)/paper-chip-section.md
	sed '/<!-- make paper-chip: begin -->/,/<!-- make paper-chip: end -->/d' docs/validation-data.md > $(BUILD)/validation-data.md
	cat $(BUILD)/validation-data.md $(BUILD)/paper-chip-section.md > docs/validation-data.md
	gnuplot -e "set terminal pngcairo size 800,500; set output 'docs/img/paper-chip-fps.png'; \
		set logscale xy 2; set xlabel 'cores K'; set ylabel 'fps (1024 x 1024, 64 spp), 95 % interval'; \
		set key top left; set grid; \
		plot '$(BUILD)/paper-chip.dat' using 1:2:3:4 with yerrorlines title 'DDR4-2400 x 2, 4 MB L2', \
		'' using 1:5:6:7 with yerrorlines title 'GDDR6 x 16, 8 MB L2'"

bench: deps
	@$(MAKE) --no-print-directory $(BUILD)/bench/core_speed $(BUILD)/bench/embree_xcheck $(BUILD)/bench/functional_speed \
		$(BUILD)/bench/detailed_speed $(BUILD)/bench/speed_vs_error $(BUILD)/bench/per_ray $(BUILD)/bench/sched_speed \
		$(BUILD)/bench/chip_speed $(BUILD)/bench/chip_error
	$(BUILD)/bench/core_speed
	$(BUILD)/bench/embree_xcheck
	$(BUILD)/bench/functional_speed
	$(BUILD)/bench/detailed_speed
	$(BUILD)/bench/speed_vs_error out/bench
	$(BUILD)/bench/per_ray
	$(BUILD)/bench/sched_speed
	$(BUILD)/bench/chip_speed
	$(BUILD)/bench/chip_error out/bench

# ---- the example `make run` executes --------------------------------------------------------
# The default scene on the default machine in detailed mode, sized to take one to two minutes
# (2 cores): 512 x 512 pixels, 48 samples per pixel.
RUN_SIZE ?= --set render.width=512 --set render.height=512 --set render.spp=48
run-built: all
	@echo "== sfsim: the path-tracing kernel renders the Cornell box on the timed machine (configs/streamray.ini, detailed mode)"
	bin/sfsim run -s scenes/cornell/scene.ini -c configs/streamray.ini $(RUN_SIZE) -o out
	@cat out/report.txt
	@echo "== outputs: out/frame.png (tone-mapped), out/frame.exr (linear), out/cost.png (cycles per pixel),"
	@echo "==          out/report.txt (above), out/report.json (everything; docs/report.md)"
	@grep -E '^cycles +[0-9]' out/report.txt | sed 's/^/== headline: /'

# ---- installation (docs/install.md) ---------------------------------------------------------
# PREFIX/bin: sfsim, sfasm; PREFIX/lib/sfsim: the image library sfsim loads when it reads images;
# PREFIX/share/sfsim: kernels, configs, the default scene (sfsim finds these and the library from
# its own folder); PREFIX/share/doc/sfsim: README and docs.
PREFIX  ?= /usr/local
DATADIR := $(DESTDIR)$(PREFIX)/share/sfsim
DOCDIR  := $(DESTDIR)$(PREFIX)/share/doc/sfsim
SHIPPED_SCENES := scenes/cornell/scene.ini scenes/cornell/glossy.ini scenes/cornell/analytic.ini \
                  scenes/cornell/cornell-box.gltf scenes/cornell/cornell-box.bin

install: all
	install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(PREFIX)/lib/sfsim $(DATADIR)/kernels/lib $(DATADIR)/kernels/filters $(DATADIR)/kernels/bench $(DATADIR)/kernels/examples \
	    $(DATADIR)/configs/sweeps $(DATADIR)/scenes/cornell $(DOCDIR)/docs
	install -m 755 bin/sfsim bin/sfasm $(DESTDIR)$(PREFIX)/bin/
	install -m 644 $(IMGLIB) $(IMGLIB).deps $(DESTDIR)$(PREFIX)/lib/sfsim/
	install -m 644 kernels/*.s $(DATADIR)/kernels/
	install -m 644 kernels/lib/* $(DATADIR)/kernels/lib/
	install -m 644 kernels/filters/* $(DATADIR)/kernels/filters/
	install -m 644 kernels/bench/* $(DATADIR)/kernels/bench/
	install -m 644 kernels/examples/* $(DATADIR)/kernels/examples/
	install -m 644 configs/*.ini $(DATADIR)/configs/
	install -m 644 configs/sweeps/*.ini $(DATADIR)/configs/sweeps/
	install -m 644 $(SHIPPED_SCENES) $(DATADIR)/scenes/cornell/
	install -m 644 README.md LICENSE $(DOCDIR)/
	install -m 644 docs/*.md $(wildcard docs/*.png) $(DOCDIR)/docs/
	@echo "installed sfsim into $(DESTDIR)$(PREFIX) (data: $(PREFIX)/share/sfsim)"

# What make install put there, and nothing else: the two programs and sfsim's own folders.
uninstall:
	rm -f $(DESTDIR)$(PREFIX)/bin/sfsim $(DESTDIR)$(PREFIX)/bin/sfasm
	rm -rf $(DESTDIR)$(PREFIX)/lib/sfsim $(DATADIR) $(DOCDIR)
	@echo "removed sfsim from $(DESTDIR)$(PREFIX)"

clean:
	rm -rf $(BUILD) bin lib

-include $(shell find $(BUILD) -name '*.d' 2>/dev/null)
