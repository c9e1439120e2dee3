# clpt — an OpenCL path tracer over a kd-tree. See README.md.
#
#   make            build build/clpt
#   make test       build and run the test suite (ends with "N passed, M failed")
#   make render     render the default scene to cornell-box.png
#   make bench      throughput benchmarks (bench/)
#
# Every target first checks the system packages (tools/deps.sh): installs them when run
# as root, prints the exact apt-get line otherwise.

# ---------------------------------------------------------------- settings
PROG      := clpt
BUILD     ?= build
CC        ?= cc
OPT       ?= -O2
WARN      := -Wall -Wextra -Wpedantic -Wshadow -Wstrict-prototypes -Wmissing-prototypes \
             -Wold-style-definition -Wformat=2 -Wundef -Wpointer-arith \
             -Wwrite-strings -Wvla -Wcast-align -Wswitch-enum
# The scalar device must compute the same bits as OpenCL: no contraction into FMA, no
# fast-math (see kernels/compat.h).
FPFLAGS   := -ffp-contract=off -fno-fast-math
CPPFLAGS  := -D_GNU_SOURCE -DCL_TARGET_OPENCL_VERSION=120 -Ihost -Ikernels -I$(BUILD) \
             -I/usr/include/stb
CFLAGS    := -std=c11 $(OPT) -g $(WARN) $(FPFLAGS) -pthread $(EXTRA_CFLAGS)
LDFLAGS   := -pthread $(EXTRA_LDFLAGS)
LDLIBS    := -lOpenCL -lstb -lm

# Code that compiles the kernel sources as C must not promote floats to double, or the
# scalar device would round differently from OpenCL.
KERNEL_C_WARN := -Wdouble-promotion -Werror=double-promotion

HOST_SRC  := $(filter-out host/main.c,$(wildcard host/*.c))
HOST_OBJ  := $(HOST_SRC:host/%.c=$(BUILD)/host/%.o) $(BUILD)/kernel_source.o
KERNELS   := $(wildcard kernels/*.h kernels/*.cl)
TEST_SRC  := $(wildcard tests/test_*.c)
TEST_BIN  := $(TEST_SRC:tests/%.c=$(BUILD)/tests/%)
BENCH_SRC := $(wildcard bench/bench_*.c)
BENCH_BIN := $(BENCH_SRC:bench/%.c=$(BUILD)/bench/%)
DEPS_OK   := $(BUILD)/.deps-ok

.PHONY: all deps test render bench clean
.DEFAULT_GOAL := all

all: $(BUILD)/$(PROG)

# ---------------------------------------------------------------- system packages
# The stamp is refreshed only when the check passes, so a later removal is noticed by
# `make deps` (always run by test/render/bench) even if the stamp exists.
deps:
	@sh tools/deps.sh base
	@mkdir -p $(BUILD) && touch $(DEPS_OK)

$(DEPS_OK):
	@sh tools/deps.sh base
	@mkdir -p $(BUILD) && touch $@

# ---------------------------------------------------------------- build
$(BUILD)/embed: tools/embed.c | $(DEPS_OK)
	@mkdir -p $(@D)
	$(CC) -std=c11 -O1 -Wall -Wextra -o $@ $<

# Writes scenes/one-weekend.scene (tests/test_scene.c checks the committed copy).
$(BUILD)/gen_weekend: tools/gen_weekend.c | $(DEPS_OK)
	@mkdir -p $(@D)
	$(CC) -std=c11 -O1 -Wall -Wextra -o $@ $<

# Writes a closed sphere mesh of any size as a binary PLY (docs/meshes.md).
$(BUILD)/gen_mesh: tools/gen_mesh.c $(BUILD)/lib$(PROG).a
	$(CC) $(CPPFLAGS) $(CFLAGS) -o $@ $< $(BUILD)/lib$(PROG).a $(LDFLAGS) $(LDLIBS)

$(BUILD)/kernel_source.c: $(KERNELS) $(BUILD)/embed
	$(BUILD)/embed clpt_kernel_source kernels/entry.cl > $@.tmp && mv $@.tmp $@

$(BUILD)/kernel_source.o: $(BUILD)/kernel_source.c
	$(CC) $(CPPFLAGS) $(CFLAGS) -c -o $@ $<

$(BUILD)/host/%.o: host/%.c $(DEPS_OK)
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(CFLAGS) $(FILE_WARN) -MMD -MP -c -o $@ $<

$(BUILD)/host/device_cpu.o: FILE_WARN := $(KERNEL_C_WARN)

$(BUILD)/lib$(PROG).a: $(HOST_OBJ)
	rm -f $@ && ar rcs $@ $^

$(BUILD)/$(PROG): $(BUILD)/host/main.o $(BUILD)/lib$(PROG).a
	$(CC) $(LDFLAGS) -o $@ $^ $(LDLIBS)

$(BUILD)/tests/%: tests/%.c tests/harness.h $(BUILD)/lib$(PROG).a
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) -Itests $(CFLAGS) -MMD -MP -o $@ $< $(BUILD)/lib$(PROG).a $(LDFLAGS) $(LDLIBS)

$(BUILD)/bench/%: bench/%.c $(BUILD)/lib$(PROG).a
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(CFLAGS) -MMD -MP -o $@ $< $(BUILD)/lib$(PROG).a $(LDFLAGS) $(LDLIBS)

# The traversal benchmark compares with Embree 3: only it links libembree3, and only
# `make bench` builds it, so the renderer and the tests never need Embree.
$(BUILD)/.embree-ok:
	@sh tools/deps.sh embree
	@mkdir -p $(BUILD) && touch $@

$(BUILD)/bench/bench_traverse: LDLIBS += -lembree3
$(BUILD)/bench/bench_traverse: | $(BUILD)/.embree-ok

-include $(wildcard $(BUILD)/host/*.d $(BUILD)/tests/*.d $(BUILD)/bench/*.d)

# ---------------------------------------------------------------- use
test: deps $(BUILD)/$(PROG) $(TEST_BIN)
	@sh tests/run.sh $(BUILD)

render: deps $(BUILD)/$(PROG)
	$(BUILD)/$(PROG) scenes/cornell-box.scene -o cornell-box.png

bench: deps $(BUILD)/$(PROG) $(BENCH_BIN)
	@sh bench/run.sh $(BUILD)

clean:
	rm -rf $(BUILD)
