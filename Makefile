# clpt — an OpenCL path tracer over a kd-tree. See README.md.
#
#   make            build build/clpt
#   make test       build and run the test suite (ends with "N passed, M failed")
#   make install    install under PREFIX (/usr/local), into DESTDIR if set; make uninstall
#   make render     render the default scene to cornell-box.png
#   make bench      throughput benchmarks (bench/)
#   make bench-peers  clpt against Mitsuba 3 and Cycles at equal error (bench/peers.py);
#                   PBRT=/path/to/pbrt adds pbrt-v4 on scenes written as pbrt-v4 files,
#                   PBRT_SCENES=DIR (pbrt-v4-scenes) its killeroo-simple.pbrt
#   make xcheck     single-feature scenes against Mitsuba 3 and Cycles (tools/xcheck/);
#                   PBRT=/path/to/pbrt adds the pbrt-v4 media scenes against that binary
#   make test-asan  the test suite built with AddressSanitizer + UBSan (build-asan/)
#   make test-valgrind  small renders (PoCL and scalar) under valgrind memcheck
#   make fuzz       each libFuzzer target in fuzz/ for FUZZ_SECONDS (build-fuzz/)
#
# docs/hardening.md describes the last three; docs/fuzzing.md how to add a fuzz target.
# Packages are installed by run.sh and .ci/run (tools/deps.sh), never by a make target:
# `make deps` installs the build's packages by hand; the Embree benchmark and the
# hardening targets only check theirs and print the exact apt-get line when one is missing.

# ---------------------------------------------------------------- settings
PROG      := clpt
BUILD     ?= build
CC        ?= cc
OPT       ?= -O2
WARN      := -Wall -Wextra -Wpedantic -Wshadow -Wstrict-prototypes -Wmissing-prototypes \
             -Wold-style-definition -Wformat=2 -Wundef -Wpointer-arith \
             -Wwrite-strings -Wvla -Wcast-align -Wswitch-enum
# The scalar device must compute the same bits as OpenCL: no contraction into FMA, no
# fast-math (see kernels/util/compat.h).
FPFLAGS   := -ffp-contract=off -fno-fast-math
CPPFLAGS  := -D_GNU_SOURCE -DCL_TARGET_OPENCL_VERSION=120 -Ihost -Ikernels -Iinclude -I$(BUILD)/include -I$(BUILD) \
             -I/usr/include/stb -I/usr/include/OpenEXR
# One object set serves the program, the tests and libclpt.so: position-independent,
# and hidden unless marked CLPT_API (include/clpt/clpt.h), so that the shared library
# exports the public functions only. Hidden symbols cannot be interposed, so the code is
# what the compiler's default -fPIE makes (docs/api.md has the timing).
CFLAGS    := -std=c11 $(OPT) -g $(WARN) $(FPFLAGS) -pthread -fPIC -fvisibility=hidden $(EXTRA_CFLAGS)
LDFLAGS   := -pthread $(EXTRA_LDFLAGS)
LDLIBS    := -lOpenCL -lstb -lpng -lOpenEXRCore -lOpenEXR -lstdc++ -lcjson -lz -lm
# host/io/exr_imf.cpp is clpt's one C++ file: OpenEXR's C++ reader, for the EXR images
# its C interfaces cannot decode as floats (host/io/exr_imf.h says which). The C
# compiler's driver compiles it as C++ (gcc and clang alike), with the C build's
# optimisation and instrumentation; the sanitizer builds leave out UBSan's checks that
# need its C++ runtime (vptr, function), which a program linked by the C driver lacks.
CXX_SAN_OFF := -fno-sanitize=vptr,function
CXX_FLAGS := -x c++ -std=c++14 $(OPT) -g -Wall -Wextra -Wshadow -pthread -fPIC -fvisibility=hidden \
             $(EXTRA_CFLAGS) $(if $(findstring -fsanitize,$(EXTRA_CFLAGS)),$(CXX_SAN_OFF)) \
             -Ihost -isystem /usr/include/OpenEXR -isystem /usr/include/Imath

# Open MPI (docs/distributed.md): only host/dist/mpi_driver.c includes mpi.h, and only
# the clpt program links libmpi; the tests and benchmarks never pull that file in.
MPI_CFLAGS := $(shell pkg-config --cflags ompi-c 2>/dev/null || echo -I/usr/lib/x86_64-linux-gnu/openmpi/include)
MPI_LIBS   := $(shell pkg-config --libs ompi-c 2>/dev/null || echo -lmpi)

# The version is the VERSION file's one line (semantic versioning, CHANGELOG.md); the
# commit is git's, when this folder is a git checkout (a worktree's .git is a file),
# with -dirty for changes not committed. Only build/version.o holds them.
VERSION    := $(shell cat VERSION)
GIT_COMMIT := $(shell test -e .git && git rev-parse --short=12 HEAD 2>/dev/null)
GIT_DIRTY  := $(if $(GIT_COMMIT),$(shell git diff --quiet HEAD -- 2>/dev/null || echo -dirty))
COMMIT     := $(if $(GIT_COMMIT),$(GIT_COMMIT)$(GIT_DIRTY),unknown)

# Code that compiles the kernel sources as C must not promote floats to double, or the
# scalar device would round differently from OpenCL.
KERNEL_C_WARN := -Wdouble-promotion -Werror=double-promotion
# The scalar device's builds of the kernels (host/device/scalar_paths_*.c) are compiled by
# clang where it is installed: pocl-opencl-icd, in tools/deps.sh's base profile, depends
# on clang-15, so every machine that builds clpt from the README has it. From the same
# kernel code, clang's walk traced 1.2-1.5 times gcc 12's diffuse rays per second in
# bench_traverse (Sponza's shadow rays 0.8 times) and the scalar device rendered 6-19%
# faster (bench/RESULTS.md, "The scalar device compiled by clang"); the images are the
# same bits (FPFLAGS: IEEE operations only). Any C compiler serves: SCALAR_CC=cc uses gcc.
ifeq ($(origin SCALAR_CC),undefined)
SCALAR_CC := $(firstword $(shell command -v clang-15 clang 2>/dev/null) $(CC))
endif
# Their debug information as DWARF 4: Debian 12's valgrind (3.19, make test-valgrind)
# cannot read the DWARF 5 forms clang 15 writes by default and gives up on the program.
SCALAR_CFLAGS := -gdwarf-4

HOST_SRC  := $(filter-out host/main.c,$(wildcard host/*.c host/*/*.c))
HOST_CXX_SRC := $(wildcard host/*/*.cpp)
HOST_OBJ  := $(HOST_SRC:host/%.c=$(BUILD)/host/%.o) $(HOST_CXX_SRC:host/%.cpp=$(BUILD)/host/%.o) \
             $(BUILD)/kernel_source.o \
             $(BUILD)/bench_kernel_source.o
KERNELS   := $(wildcard kernels/*.h kernels/*.cl kernels/*/*.h kernels/*/*.cl)
TEST_SRC  := $(wildcard tests/test_*.c)
TEST_BIN  := $(TEST_SRC:tests/%.c=$(BUILD)/tests/%)
# Every fuzz/fuzz_NAME.c is a libFuzzer target (make fuzz) and, linked with
# fuzz/replay.c, the test build/tests/test_fuzz_NAME, which replays its regression files
# (tests/data/fuzz/NAME/) and seed files through the same entry point.
FUZZ_SRC  := $(wildcard fuzz/fuzz_*.c)
FUZZ_REPLAY := $(FUZZ_SRC:fuzz/fuzz_%.c=$(BUILD)/tests/test_fuzz_%)
FUZZ_BIN  := $(FUZZ_SRC:fuzz/%.c=$(BUILD)/fuzz/%)
BENCH_SRC := $(wildcard bench/bench_*.c)
BENCH_BIN := $(BENCH_SRC:bench/%.c=$(BUILD)/bench/%)

.PHONY: FORCE all lib deps install uninstall deb test render bench bench-peers xcheck clean test-asan test-valgrind fuzz fuzz-build
.DEFAULT_GOAL := all

# The man page and the shell completions, written from the option list (docs/cli.md).
GENERATED_DOCS := $(BUILD)/$(PROG).1 $(BUILD)/$(PROG).bash $(BUILD)/_$(PROG)

all: $(BUILD)/$(PROG) lib $(GENERATED_DOCS)

# ---------------------------------------------------------------- system packages
deps:
	@sh tools/deps.sh base

# ---------------------------------------------------------------- build
$(BUILD)/embed: tools/embed.c
	@mkdir -p $(@D)
	$(CC) -std=c11 -O1 -Wall -Wextra -o $@ $<

# Writes scenes/one-weekend.scene (tests/test_scene.c checks the committed copy).
$(BUILD)/gen_weekend: tools/gen_weekend.c
	@mkdir -p $(@D)
	$(CC) -std=c11 -O1 -Wall -Wextra -o $@ $<

# Writes a closed sphere mesh of any size as a binary PLY (docs/meshes.md).
$(BUILD)/gen_mesh: tools/gen_mesh.c $(BUILD)/lib$(PROG).a
	$(CC) $(CPPFLAGS) $(CFLAGS) -o $@ $< $(BUILD)/lib$(PROG).a $(LDFLAGS) $(LDLIBS)

# Writes the man page and the completions from host/options.c's list (tools/clpt_docs.c).
$(BUILD)/clpt_docs: tools/clpt_docs.c $(BUILD)/version.o $(BUILD)/lib$(PROG).a
	$(CC) $(CPPFLAGS) $(CFLAGS) -o $@ $< $(BUILD)/version.o $(BUILD)/lib$(PROG).a $(LDFLAGS) $(LDLIBS)

$(BUILD)/$(PROG).1: $(BUILD)/clpt_docs
	$(BUILD)/clpt_docs man > $@.tmp && mv $@.tmp $@
$(BUILD)/$(PROG).bash: $(BUILD)/clpt_docs
	$(BUILD)/clpt_docs bash > $@.tmp && mv $@.tmp $@
$(BUILD)/_$(PROG): $(BUILD)/clpt_docs
	$(BUILD)/clpt_docs zsh > $@.tmp && mv $@.tmp $@

# The renderer's program (kernels/entry.cl) and the traversal benchmark's
# (kernels/bench/trace.cl), each flattened into a C array. The second is a member of the
# library that only bench_traverse and test_kernels pull in.
$(BUILD)/kernel_source.c: $(KERNELS) $(BUILD)/embed
	$(BUILD)/embed clpt_kernel_source kernels/entry.cl kernels > $@.tmp && mv $@.tmp $@

$(BUILD)/bench_kernel_source.c: $(KERNELS) $(BUILD)/embed
	$(BUILD)/embed clpt_bench_kernel_source kernels/bench/trace.cl kernels > $@.tmp && mv $@.tmp $@

$(BUILD)/kernel_source.o $(BUILD)/bench_kernel_source.o: %.o: %.c
	$(CC) $(CPPFLAGS) $(CFLAGS) -c -o $@ $<

# Rewritten only when the version or the commit changed, so that an unchanged build
# links nothing again.
$(BUILD)/version.c: VERSION FORCE
	@mkdir -p $(@D)
	@printf '/* written by the Makefile from VERSION and git */\n#include "version.h"\nconst char clpt_version_text[] = "%s";\nconst char clpt_commit[] = "%s";\n' \
	    '$(VERSION)' '$(COMMIT)' > $@.tmp
	@if cmp -s $@.tmp $@; then rm -f $@.tmp; else mv $@.tmp $@; fi

# The public header's version macros, from the same VERSION (include/clpt/clpt.h
# includes it; installed beside it).
VERSION_H := $(BUILD)/include/$(PROG)/clpt_version.h
$(VERSION_H): VERSION
	@mkdir -p $(@D)
	@printf '/* written by the Makefile from VERSION: do not edit */\n#ifndef CLPT_VERSION_MACROS_H\n#define CLPT_VERSION_MACROS_H\n#define CLPT_VERSION_MAJOR %s\n#define CLPT_VERSION_MINOR %s\n#define CLPT_VERSION_PATCH %s\n#endif\n' \
	    $(subst ., ,$(VERSION)) > $@.tmp && mv $@.tmp $@

$(BUILD)/version.o: $(BUILD)/version.c host/version.h
	$(CC) $(CPPFLAGS) $(CFLAGS) -c -o $@ $<

FORCE:

# The compile flags as last used: objects built with other flags (an older checkout,
# another EXTRA_CFLAGS) are rebuilt rather than linked with the new ones.
$(BUILD)/.flags: FORCE
	@mkdir -p $(@D)
	@echo '$(CC) $(SCALAR_CC) $(SCALAR_CFLAGS) $(CPPFLAGS) $(CFLAGS)' > $@.tmp
	@if cmp -s $@.tmp $@; then rm -f $@.tmp; else mv $@.tmp $@; fi

$(BUILD)/host/%.o: host/%.c $(BUILD)/.flags | $(VERSION_H)
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(CFLAGS) $(FILE_WARN) -MMD -MP -c -o $@ $<

$(BUILD)/host/%.o: host/%.cpp $(BUILD)/.flags
	@mkdir -p $(@D)
	$(CC) $(CXX_FLAGS) -MMD -MP -c -o $@ $<

# The scalar device and its builds of the kernels (scalar_paths_NAME.c, each with its own
# CLPT_FEATURES, compiled by SCALAR_CC), all with the same FPFLAGS as every object.
$(BUILD)/host/device/device_scalar.o $(BUILD)/host/device/scalar_paths_%.o: FILE_WARN := $(KERNEL_C_WARN)
$(BUILD)/host/device/scalar_paths_%.o: host/device/scalar_paths_%.c $(BUILD)/.flags | $(VERSION_H)
	@mkdir -p $(@D)
	$(SCALAR_CC) $(CPPFLAGS) $(CFLAGS) $(SCALAR_CFLAGS) $(FILE_WARN) -MMD -MP -c -o $@ $<
$(BUILD)/host/dist/mpi_driver.o $(BUILD)/host/dist/mpi_wire.o $(BUILD)/host/dist/mpi_workers.o: FILE_WARN := $(MPI_CFLAGS)

# On x86-64 the scalar device's builds of the kernels twice more, for processors with AVX2
# and for those with AVX-512 (x86-64-v4: F, VL, BW, DQ, CD; host/device/scalar_paths.h);
# the processor picks at run time.
ifneq ($(findstring x86_64,$(shell $(CC) -dumpmachine)),)
SCALAR_AVX2_OBJ := $(patsubst host/device/%.c,$(BUILD)/host/device/%.avx2.o,$(wildcard host/device/scalar_paths_*.c))
SCALAR_AVX512_OBJ := $(patsubst host/device/%.c,$(BUILD)/host/device/%.avx512.o,$(wildcard host/device/scalar_paths_*.c))
HOST_OBJ += $(SCALAR_AVX2_OBJ) $(SCALAR_AVX512_OBJ)
$(BUILD)/host/device/%.avx2.o: host/device/%.c $(BUILD)/.flags | $(VERSION_H)
	@mkdir -p $(@D)
	$(SCALAR_CC) $(CPPFLAGS) $(CFLAGS) $(SCALAR_CFLAGS) $(KERNEL_C_WARN) -mavx2 -DSCALAR_PATHS_AVX2 -MMD -MP -c -o $@ $<
$(BUILD)/host/device/%.avx512.o: host/device/%.c $(BUILD)/.flags | $(VERSION_H)
	@mkdir -p $(@D)
	$(SCALAR_CC) $(CPPFLAGS) $(CFLAGS) $(SCALAR_CFLAGS) $(KERNEL_C_WARN) -march=x86-64-v4 -DSCALAR_PATHS_AVX512 -MMD -MP -c -o $@ $<
endif

$(BUILD)/lib$(PROG).a: $(HOST_OBJ)
	rm -f $@ && ar rcs $@ $^

# Only the program links SDL2 (the viewer, --interactive); the tests and benchmarks use
# the library without it.
$(BUILD)/$(PROG): $(BUILD)/host/main.o $(BUILD)/version.o $(BUILD)/lib$(PROG).a
	$(CC) $(LDFLAGS) -o $@ $^ $(LDLIBS) $(MPI_LIBS) -lSDL2

# ---------------------------------------------------------------- the shared library
# libclpt.so.MAJOR.MINOR.PATCH (SONAME libclpt.so.MAJOR), the version read from the public
# header. Everything but the viewer (SDL2), the distributed renders (MPI) and the
# program's own files (main, its output files, its stop signals): the library links
# neither SDL2 nor MPI, and keeps no global state.
API_VERSION := $(VERSION)
API_MAJOR   := $(firstword $(subst ., ,$(API_VERSION)))
SO_NAME     := lib$(PROG).so.$(API_MAJOR)
SO_FILE     := $(BUILD)/lib$(PROG).so.$(API_VERSION)
# Every symbol the library needs resolved at its link (-z defs), except under the
# sanitizers, whose runtime the program loading the library provides.
SO_DEFS     ?= -Wl,--no-undefined -Wl,-z,defs
SO_OBJ      := $(filter-out $(BUILD)/host/viewer/% $(BUILD)/host/dist/% $(BUILD)/host/outputs.o \
                            $(BUILD)/host/stop_signal.o,$(HOST_OBJ))

lib: $(BUILD)/lib$(PROG).so

$(SO_FILE): $(SO_OBJ) host/api/libclpt.map
	$(CC) -shared -Wl,-soname,$(SO_NAME) -Wl,--version-script=host/api/libclpt.map $(SO_DEFS) \
	    $(LDFLAGS) -o $@ $(SO_OBJ) $(LDLIBS)

$(BUILD)/lib$(PROG).so: $(SO_FILE)
	ln -sf $(notdir $(SO_FILE)) $(BUILD)/$(SO_NAME)
	ln -sf $(SO_NAME) $@

# The example and the API's test see the public header only, and link the shared
# library (found beside them through the run path), as a user's program does.
# (EXTRA_CFLAGS and LDFLAGS: a sanitizer build's program carries the runtime its
# library needs.)
API_CFLAGS := -std=c11 $(OPT) -g $(WARN) -Iinclude -I$(BUILD)/include $(EXTRA_CFLAGS)
$(BUILD)/examples/%: examples/%.c include/clpt/clpt.h $(VERSION_H) $(BUILD)/lib$(PROG).so
	@mkdir -p $(@D)
	$(CC) $(API_CFLAGS) $(LDFLAGS) -o $@ $< -L$(BUILD) -l$(PROG) -Wl,-rpath,'$$ORIGIN/..'

$(BUILD)/tests/test_api: tests/test_api.c tests/harness.h include/clpt/clpt.h $(VERSION_H) $(BUILD)/lib$(PROG).so
	@mkdir -p $(@D)
	$(CC) $(API_CFLAGS) $(LDFLAGS) -D_GNU_SOURCE -Itests -DCLPT_BUILD_DIR='"$(BUILD)"' -pthread -o $@ $< \
	    -L$(BUILD) -l$(PROG) -Wl,-rpath,'$$ORIGIN/..' -lm

$(BUILD)/tests/%: tests/%.c tests/harness.h $(BUILD)/lib$(PROG).a
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) -Itests -DCLPT_BUILD_DIR='"$(BUILD)"' $(CFLAGS) -MMD -MP -o $@ $< $(BUILD)/lib$(PROG).a $(LDFLAGS) $(LDLIBS)

$(BUILD)/tests/test_fuzz_%: fuzz/fuzz_%.c fuzz/replay.c fuzz/fuzz.h tests/harness.h $(BUILD)/lib$(PROG).a
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) -Itests -Ifuzz -DFUZZ_NAME='"$*"' $(CFLAGS) -o $@ $< fuzz/replay.c $(BUILD)/lib$(PROG).a $(LDFLAGS) $(LDLIBS)

# Only built by `make fuzz`, where CC is clang and the library is instrumented.
$(BUILD)/fuzz/%: fuzz/%.c fuzz/fuzz.h $(BUILD)/lib$(PROG).a
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) -Ifuzz $(CFLAGS) -fsanitize=fuzzer -o $@ $< $(BUILD)/lib$(PROG).a $(LDFLAGS) $(LDLIBS)

$(BUILD)/bench/%: bench/%.c $(BUILD)/lib$(PROG).a
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(CFLAGS) -MMD -MP -o $@ $< $(BUILD)/lib$(PROG).a $(LDFLAGS) $(LDLIBS)

# The traversal and build benchmarks compare with Embree 3: only they link libembree3, and only
# `make bench` builds it, so the renderer and the tests never need Embree.
$(BUILD)/.embree-ok:
	@sh tools/deps.sh --check embree
	@mkdir -p $(BUILD) && touch $@

$(BUILD)/bench/bench_traverse $(BUILD)/bench/bench_build: LDLIBS += -lembree3
$(BUILD)/bench/bench_traverse $(BUILD)/bench/bench_build: | $(BUILD)/.embree-ok

-include $(wildcard $(BUILD)/host/*.d $(BUILD)/host/*/*.d $(BUILD)/tests/*.d $(BUILD)/bench/*.d)

# ---------------------------------------------------------------- install
# `make install PREFIX=/usr DESTDIR=/tmp/stage` as packagers expect: PREFIX is where
# clpt will live (written into clpt.pc), DESTDIR where the files go now. The program
# needs nothing from the source tree at run time (the kernels are built into it).
PREFIX      ?= /usr/local
BINDIR      ?= $(PREFIX)/bin
LIBDIR      ?= $(PREFIX)/lib
INCLUDEDIR  ?= $(PREFIX)/include
MANDIR      ?= $(PREFIX)/share/man
BASHCOMPDIR ?= $(PREFIX)/share/bash-completion/completions
ZSHCOMPDIR  ?= $(PREFIX)/share/zsh/site-functions
PKGCONFIGDIR ?= $(LIBDIR)/pkgconfig
INSTALL     ?= install

# The public C API is installed where it has been built: every file these patterns
# match when the recipe runs (the shared library with its SONAME links, copied as
# links; the headers of include/clpt/), and then clpt.pc. Extend the patterns, not
# the recipe.
INSTALL_LIBS    ?= $(BUILD)/lib$(PROG).so*
INSTALL_HEADERS ?= include/$(PROG)/*.h $(BUILD)/include/$(PROG)/*.h

# Open Image Denoise (--denoise), when `sh tools/deps.sh oidn` has fetched it into
# BUILD/oidn: copied whole (its libraries, TBB, SOURCE) to BINDIR/../lib/clpt/oidn, the
# one folder relative to the program that clpt's dlopen search looks in once installed
# (host/render/denoise.c; docs/denoise.md). A private folder, not LIBDIR itself, so that
# its own TBB never shadows a system one. INSTALL_OIDN=0 leaves it out (make deb does: a
# Debian package depends on packaged libraries, not on a wheel's binaries).
INSTALL_OIDN    ?= 1
OIDN_INSTALL_DIR = $(BINDIR)/../lib/$(PROG)/oidn

$(BUILD)/$(PROG).pc: tools/$(PROG).pc.in VERSION FORCE
	@sed -e 's|@PREFIX@|$(PREFIX)|' -e 's|@LIBDIR@|$(LIBDIR)|' -e 's|@INCLUDEDIR@|$(INCLUDEDIR)|' \
	    -e 's|@VERSION@|$(VERSION)|' $< > $@.tmp
	@if cmp -s $@.tmp $@; then rm -f $@.tmp; else mv $@.tmp $@; fi

# INSTALL_NO_BUILD=1 copies what BUILD holds without building it first: tests/test_install
# runs `make install` in the middle of `make test` (and test-asan), where a build with
# the plain flags would replace the build folder's objects.
install: $(if $(INSTALL_NO_BUILD),,all) $(BUILD)/$(PROG).pc
	$(INSTALL) -d $(DESTDIR)$(BINDIR) $(DESTDIR)$(MANDIR)/man1 $(DESTDIR)$(BASHCOMPDIR) $(DESTDIR)$(ZSHCOMPDIR)
	$(INSTALL) -m 755 $(BUILD)/$(PROG) $(DESTDIR)$(BINDIR)/$(PROG)
	$(INSTALL) -m 644 $(BUILD)/$(PROG).1 $(DESTDIR)$(MANDIR)/man1/$(PROG).1
	$(INSTALL) -m 644 $(BUILD)/$(PROG).bash $(DESTDIR)$(BASHCOMPDIR)/$(PROG)
	$(INSTALL) -m 644 $(BUILD)/_$(PROG) $(DESTDIR)$(ZSHCOMPDIR)/_$(PROG)
	@set -e; libs=$$(ls -d $(INSTALL_LIBS) 2>/dev/null || true); \
	if [ -n "$$libs" ]; then \
	    echo install $$libs "->" $(DESTDIR)$(LIBDIR); \
	    $(INSTALL) -d $(DESTDIR)$(LIBDIR) && cp -P $$libs $(DESTDIR)$(LIBDIR)/; \
	fi; \
	headers=$$(ls -d $(INSTALL_HEADERS) 2>/dev/null || true); \
	if [ -n "$$headers" ]; then \
	    echo install $$headers "->" $(DESTDIR)$(INCLUDEDIR)/$(PROG); \
	    $(INSTALL) -d $(DESTDIR)$(INCLUDEDIR)/$(PROG) $(DESTDIR)$(PKGCONFIGDIR); \
	    $(INSTALL) -m 644 $$headers $(DESTDIR)$(INCLUDEDIR)/$(PROG)/; \
	    $(INSTALL) -m 644 $(BUILD)/$(PROG).pc $(DESTDIR)$(PKGCONFIGDIR)/$(PROG).pc; \
	fi; \
	if [ "$(INSTALL_OIDN)" = 1 ] && [ -e $(BUILD)/oidn/lib/libOpenImageDenoise.so.2 ]; then \
	    echo install $(BUILD)/oidn "->" $(DESTDIR)$(OIDN_INSTALL_DIR); \
	    rm -rf $(DESTDIR)$(OIDN_INSTALL_DIR) && $(INSTALL) -d $(DESTDIR)$(OIDN_INSTALL_DIR) && \
	    cp -RP $(BUILD)/oidn/. $(DESTDIR)$(OIDN_INSTALL_DIR)/; \
	fi

# A Debian package (binary) of what `make install PREFIX=/usr` installs, built with
# dpkg-deb, its Depends from dpkg-shlibdeps (dpkg-dev): tools/make_deb.sh.
deb: all $(BUILD)/$(PROG).pc
	@sh tools/deps.sh --check deb
	@sh tools/make_deb.sh $(BUILD) $(VERSION)

uninstall:
	rm -f $(DESTDIR)$(BINDIR)/$(PROG) $(DESTDIR)$(MANDIR)/man1/$(PROG).1 $(DESTDIR)$(BASHCOMPDIR)/$(PROG) \
	      $(DESTDIR)$(ZSHCOMPDIR)/_$(PROG) $(DESTDIR)$(PKGCONFIGDIR)/$(PROG).pc
	rm -f $(DESTDIR)$(LIBDIR)/lib$(PROG).so*
	rm -rf $(DESTDIR)$(INCLUDEDIR)/$(PROG) $(DESTDIR)$(OIDN_INSTALL_DIR)
	-rmdir $(DESTDIR)$(BINDIR)/../lib/$(PROG) 2>/dev/null

# ---------------------------------------------------------------- use
EXAMPLE_BIN := $(patsubst examples/%.c,$(BUILD)/examples/%,$(wildcard examples/*.c))

# The Python module's tests, one program of the suite (tools/test_python.sh says how).
$(BUILD)/tests/test_python: tools/test_python.sh $(BUILD)/lib$(PROG).so
	@mkdir -p $(@D)
	cp tools/test_python.sh $@ && chmod +x $@

test: $(BUILD)/$(PROG) $(GENERATED_DOCS) $(BUILD)/$(PROG).pc $(TEST_BIN) $(FUZZ_REPLAY) $(EXAMPLE_BIN) \
      $(BUILD)/tests/test_python
	@sh tools/check_layers.sh
	@sh tools/check_exports.sh $(BUILD)
	@sh tools/check_kernel_warnings.sh
	@sh tests/run.sh $(BUILD)

render: $(BUILD)/$(PROG)
	$(BUILD)/$(PROG) scenes/cornell-box.scene -o cornell-box.png

bench: $(BUILD)/$(PROG) $(BENCH_BIN)
	@sh bench/run.sh $(BUILD)

# Minutes long and needs ../shared/peers; peers that are not installed are skipped.
# PBRT (a pbrt-v4 binary, never part of the repository) and PBRT_SCENES are passed on.
bench-peers: $(BUILD)/$(PROG)
	@mkdir -p $(BUILD)/pocl-cache $(BUILD)/kernel-cache
	@POCL_CACHE_DIR=$${POCL_CACHE_DIR:-$(CURDIR)/$(BUILD)/pocl-cache} \
	 CLPT_CACHE_DIR=$${CLPT_CACHE_DIR:-$(CURDIR)/$(BUILD)/kernel-cache} \
	 python3 bench/peers.py --clpt $(BUILD)/$(PROG) --out $(BUILD)/peers $(if $(PBRT),--pbrt $(PBRT)) \
	   $(if $(PBRT_SCENES),--pbrt-scenes $(PBRT_SCENES)) $(PEERS_ARGS)

# The cross-check (docs/validation.md): minutes long, not part of `make test`; Mitsuba 3
# (pip) and Cycles (Debian's blender) are used when installed and skipped otherwise.
# XCHECK_ARGS passes options, e.g. XCHECK_ARGS="--only lambert,sheen --spp 64".
xcheck: $(BUILD)/$(PROG)
	@mkdir -p $(BUILD)/pocl-cache $(BUILD)/kernel-cache
	@POCL_CACHE_DIR=$${POCL_CACHE_DIR:-$(CURDIR)/$(BUILD)/pocl-cache} \
	 CLPT_CACHE_DIR=$${CLPT_CACHE_DIR:-$(CURDIR)/$(BUILD)/kernel-cache} \
	 python3 tools/xcheck/xcheck.py --clpt $(BUILD)/$(PROG) --out $(BUILD)/xcheck $(if $(PBRT),--pbrt $(PBRT)) $(XCHECK_ARGS)

# ---------------------------------------------------------------- hardening
# The sanitizer and fuzzing builds are the ordinary build in their own folders, with
# clang and instrumentation: every host file and the scalar device (the kernels compiled
# as C) are checked; the OpenCL runtime is not instrumented (tools/sanitizers/ says
# what is suppressed there, and why).
SAN_FLAGS  := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer
SAN_ENV    := ASAN_OPTIONS=detect_stack_use_after_return=1:check_initialization_order=1:strict_init_order=1 \
              LSAN_OPTIONS=suppressions=$(CURDIR)/tools/sanitizers/lsan.supp:print_suppressions=0 \
              UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
FUZZ_SECONDS ?= 60

test-asan:
	@sh tools/deps.sh --check base sanitize
	@$(SAN_ENV) $(MAKE) --no-print-directory BUILD=build-asan CC=clang SCALAR_CC=clang OPT=-O1 SO_DEFS= \
	    EXTRA_CFLAGS="$(SAN_FLAGS)" EXTRA_LDFLAGS="$(SAN_FLAGS)" test

test-valgrind: $(BUILD)/$(PROG)
	@sh tools/deps.sh --check valgrind
	@sh tools/valgrind.sh $(BUILD)

fuzz-build:
	@sh tools/deps.sh --check base fuzz
	@$(MAKE) --no-print-directory BUILD=build-fuzz CC=clang SCALAR_CC=clang OPT=-O1 \
	    EXTRA_CFLAGS="$(SAN_FLAGS) -fsanitize=fuzzer-no-link -DCLPT_FUZZ_BUILD" EXTRA_LDFLAGS="$(SAN_FLAGS)" \
	    $(FUZZ_SRC:fuzz/%.c=build-fuzz/fuzz/%)

fuzz: fuzz-build
	@$(SAN_ENV) sh tools/fuzz.sh build-fuzz $(FUZZ_SECONDS) $(FUZZ_SRC:fuzz/fuzz_%.c=%)

clean:
	rm -rf $(BUILD) build-asan build-fuzz
