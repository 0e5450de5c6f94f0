# rtspheres: headless batch ray tracer.
#
# Targets
#   all      (default) build ./rtspheres
#   demo     install missing packages, build, render scenes/three-balls.txt to demo.png
#   test     install missing packages, build, run every test (unit, render, analytic),
#            or just the tests TESTS names (make test TESTS="test-frames test_pack")
#   bench    build with release flags and time the benchmark scenes against a plain C
#            reference and the peers (Blender Cycles, POV-Ray) in the same run (not a
#            test): a table with the targets as ratios, build/bench.csv (appended),
#            build/bench.json, build/bench-plot.png; installs the peers first
#            (bench-deps)
#   golden   re-render the golden images in golden/ (never run by the tests; say why in
#            the commit when you commit new ones)
#   deps     install the Debian packages listed in .ci/debian-packages that are missing
#   test-deps  the same for .ci/test-packages, what only the tests need (a browser)
#   bench-deps  the same for .ci/bench-packages, the bench's peers (never the tests')
#   fuzz     build the libFuzzer harnesses (tests/fuzz/) with clang into build-fuzz/ and
#            fuzz each for FUZZ_SECONDS; the corpus found grows in build-fuzz/corpus/
#   fuzz-smoke  the fuzzing check the tests run: regressions, then 10 s per harness
#   clean    remove build products
#
# Knobs
#   V=1        show the commands (and with `test`, every check a passing test makes)
#   TESTS      with `test`: the names of the tests to run (default: all of them)
#   TEST_JOBS  with `test`: how many tests run at once (default: the number of cores;
#              tests/run.sh). TEST_JOBS=1 for one at a time
#   RTSPHERES_TEST_TIMEOUT  with `test`: seconds each test may take (environment;
#              default 120 s a unit binary, 600 s a render script; tests/run.sh)
#   SAN=1      build with AddressSanitizer + UndefinedBehaviorSanitizer (into build-san/)
#   CFLAGS, CXXFLAGS, LDFLAGS   yours: appended after ours, never replacing them
#   CC, CXX    compilers (default cc, c++)
#   FUZZ_SECONDS  how long `make fuzz` runs each harness (default 60)
#   FUZZ_CC, FUZZ_CXX  the compilers of the fuzz harnesses; must have libFuzzer
#              (default clang, clang++)
#   BENCH_SPP, BENCH_REFERENCE_SPP, BENCH_SCALE, BENCH_MESH_LEVELS, BENCH_PEERS,
#   BENCH_QUALITY_*, ...  the sizes of `make bench` (environment; tests/bench/run.sh and
#              tests/bench/peers.sh say what each does)

all: rtspheres
.PHONY: all demo test bench bench-deps test-deps golden deps clean unit-tests fuzz fuzz-smoke fuzz-build

CC ?= cc
CXX ?= c++

ifeq ($(V),1)
Q :=
say = @true
else
Q := @
say = @printf '  %-7s %s\n'
endif

BUILD := build
SAN_FLAGS :=
ifeq ($(SAN),1)
BUILD := build-san
SAN_FLAGS := -fsanitize=address,undefined -fno-omit-frame-pointer
endif

PKG_CONFIG ?= pkg-config
PKGS := epoxy egl OpenImageIO tinyobjloader tinygltf cglm
PKG_CFLAGS = $(shell $(PKG_CONFIG) --cflags $(PKGS) 2>/dev/null)
PKG_LIBS = $(shell $(PKG_CONFIG) --libs $(PKGS) 2>/dev/null)
CMOCKA_LIBS = $(shell $(PKG_CONFIG) --libs cmocka 2>/dev/null)

OUR_CFLAGS := -std=c11 -D_GNU_SOURCE -Wall -Wextra -O2 -g -Icore -Iglsl -MMD -MP $(SAN_FLAGS)
OUR_CXXFLAGS := -std=c++17 -Wall -Wextra -O2 -g -Icore -MMD -MP $(SAN_FLAGS)
OUR_LDFLAGS := $(SAN_FLAGS)

CORE_C := $(wildcard core/*.c)
CORE_CXX := $(wildcard core/*.cpp)
CORE_ASM := $(wildcard core/*.S)
CLI_C := $(wildcard cli/*.c)
UNIT_TESTS_C := $(wildcard tests/unit/test_*.c)
SHADERS := $(wildcard glsl/*) core/packed_layout.h core/tracer_interface.h core/shader_sources.h

CORE_OBJ := $(CORE_C:%.c=$(BUILD)/%.o) $(CORE_CXX:%.cpp=$(BUILD)/%.o) $(CORE_ASM:%.S=$(BUILD)/%.o)
CLI_OBJ := $(CLI_C:%.c=$(BUILD)/%.o)
UNIT_TESTS := $(UNIT_TESTS_C:tests/unit/%.c=$(BUILD)/tests/%)
LIBRARY := $(BUILD)/librtspheres.a

ifeq ($(SAN),1)
PROGRAM := $(BUILD)/rtspheres
rtspheres: $(PROGRAM)
else
PROGRAM := rtspheres
endif

$(BUILD)/%.o: %.c
	$(say) CC $<
	@mkdir -p $(dir $@)
	$(Q)$(CC) $(OUR_CFLAGS) $(PKG_CFLAGS) $(CFLAGS) -c $< -o $@

$(BUILD)/%.o: %.cpp
	$(say) CXX $<
	@mkdir -p $(dir $@)
	$(Q)$(CXX) $(OUR_CXXFLAGS) $(PKG_CFLAGS) $(CXXFLAGS) -c $< -o $@

# core/postprocess_denoise.c's loops are written to be vectorised (see the file): -O3
# vectorises them, once no square root can set errno and no comparison is taken to trap
# (neither changes a value); -ffp-contract=off (C11's default, said here) keeps a multiply
# and an add apart in every CPU's clone of them, so that the image does not depend on the CPU.
$(BUILD)/core/postprocess_denoise.o: OUR_CFLAGS += -O3 -fno-math-errno -fno-trapping-math -ffp-contract=off

# The shaders are embedded with the assembler's .incbin, so the binary runs from anywhere.
$(BUILD)/%.o: %.S $(SHADERS)
	$(say) EMBED $<
	@mkdir -p $(dir $@)
	$(Q)$(CC) -Wa,-I. -c $< -o $@

$(LIBRARY): $(CORE_OBJ)
	$(say) AR $@
	$(Q)rm -f $@ && ar rcs $@ $^

# The GPU driver (loaded by EGL) must find core/large_pages.c's posix_memalign before libc's.
$(PROGRAM): $(CLI_OBJ) $(LIBRARY)
	$(say) LINK $@
	$(Q)$(CXX) $(OUR_LDFLAGS) -Wl,--export-dynamic-symbol=posix_memalign $(LDFLAGS) $(CLI_OBJ) $(LIBRARY) \
		$(PKG_LIBS) -lm -o $@

$(BUILD)/tests/%: tests/unit/%.c $(LIBRARY)
	$(say) TEST $@
	@mkdir -p $(dir $@)
	$(Q)$(CC) $(OUR_CFLAGS) $(PKG_CFLAGS) $(CFLAGS) $< -o $@ $(OUR_LDFLAGS) $(LDFLAGS) \
		$(LIBRARY) $(PKG_LIBS) $(CMOCKA_LIBS) -lstdc++ -lm

unit-tests: $(UNIT_TESTS)

# Installs what the list $(1) names and dpkg says is missing (sudo when not root); $(2)
# is the target, for the message. deps: what rtspheres and its tests need; test-deps:
# what only the tests need; bench-deps: the bench's peers.
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
define install_missing
	@missing=$$(grep -v '^\s*#' $(1) | while read -r p; do \
		[ -n "$$p" ] || continue; \
		dpkg-query -W -f='$${Status}\n' "$$p" 2>/dev/null | grep -q 'install ok installed' || echo "$$p"; \
	done | tr '\n' ' '); \
	if [ -n "$$missing" ]; then \
		echo "$(2): installing missing Debian packages: $$missing"; \
		$(SUDO) apt-get update -q && \
		$(SUDO) env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends $$missing; \
	fi
endef
deps:
	$(call install_missing,.ci/debian-packages,deps)

test-deps: deps
	$(call install_missing,.ci/test-packages,test-deps)

bench-deps:
	$(call install_missing,.ci/bench-packages,bench-deps)

demo: deps
	$(Q)$(MAKE) --no-print-directory all
	./$(PROGRAM) render scenes/three-balls.txt -o demo.png
	@echo "demo: wrote demo.png"

# The sanitizer test run (SAN=1): stop at the first report with a stack, exit 86 (not 1
# or 2, which the tests expect for other reasons) and suppress only the GL stack's own
# leaks (tests/sanitizers/lsan.supp). Every report also goes to a file in
# $(BUILD)/sanitizer-reports/, which tests/run.sh counts as a failure: a test may ignore
# a command's exit status or stderr, a report must still fail the run. Mesa unloads its
# driver in eglTerminate, which would leave its leaks without a library name to suppress
# them by; the preloaded shim keeps libraries loaded (tests/sanitizers/
# keep_libraries_loaded.c says why), which is also why ASan must not insist on being
# first in the library list.
SAN_TEST_SHIM :=
SAN_TEST_ENV :=
SAN_REPORTS := $(CURDIR)/$(BUILD)/sanitizer-reports
ifeq ($(SAN),1)
SAN_TEST_SHIM := $(BUILD)/keep-libraries-loaded.so
SAN_REPORT_OPTIONS := halt_on_error=1:print_stacktrace=1:exitcode=86:log_path=$(SAN_REPORTS)/report
SAN_TEST_ENV := ASAN_OPTIONS=$(SAN_REPORT_OPTIONS):detect_leaks=1:verify_asan_link_order=0 \
	LSAN_OPTIONS=suppressions=$(CURDIR)/tests/sanitizers/lsan.supp:print_suppressions=0 \
	UBSAN_OPTIONS=$(SAN_REPORT_OPTIONS) \
	LD_PRELOAD=$(CURDIR)/$(SAN_TEST_SHIM) \
	RTSPHERES_SANITIZER_REPORTS=$(SAN_REPORTS)
endif

$(BUILD)/keep-libraries-loaded.so: tests/sanitizers/keep_libraries_loaded.c
	$(say) CC $@
	@mkdir -p $(dir $@)
	$(Q)$(CC) -shared -fPIC -O2 -Wall -Wextra $< -o $@

test: test-deps
	$(Q)$(MAKE) --no-print-directory $(PROGRAM) unit-tests $(SAN_TEST_SHIM)
	$(Q)$(if $(SAN_TEST_ENV),rm -rf $(SAN_REPORTS) && mkdir -p $(SAN_REPORTS) && )$(SAN_TEST_ENV) V=$(V) sh tests/run.sh \
		$(BUILD) ./$(PROGRAM) $(TESTS)

# The bench compiles its own tools (the reference with -O3 -march=native -fopenmp and none
# of your CFLAGS, since it is the yardstick; the peak-RSS wrapper; the chart; the image
# error) into build/bench/, so `sh tests/bench/run.sh ./rtspheres` also works alone. A
# sanitizer build would time the sanitizers, so SAN=1 is refused. Peers that cannot be
# installed (no network) only lose their rows: run.sh skips them with a note.
bench: deps
ifeq ($(SAN),1)
	@echo "bench: times the release build; run it without SAN=1" >&2; exit 2
endif
	$(Q)$(MAKE) --no-print-directory bench-deps || \
		echo "bench: the peers of .ci/bench-packages could not be installed; their rows are skipped"
	$(Q)$(MAKE) --no-print-directory all
	$(Q)CC="$(CC)" CXX="$(CXX)" V="$(V)" sh tests/bench/run.sh ./$(PROGRAM)

golden: all
	$(Q)sh tests/render/make-golden.sh ./$(PROGRAM)

# Fuzzing. The harnesses compile the core sources they need straight into each binary,
# instrumented for libFuzzer and the sanitizers (clang only), never reusing build/ objects.
FUZZ_SECONDS ?= 60
FUZZ_CC ?= clang
FUZZ_DIR := build-fuzz
FUZZ_FLAGS := -std=c11 -D_GNU_SOURCE -g -O1 -fno-omit-frame-pointer -Icore -Iglsl \
	-fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined
# The packer and the CPU traversal of what it packs (core/pack_internal.h lists its files).
FUZZ_PACK_SOURCES := core/pack.c core/pack_collect.c core/pack_geometry.c core/pack_lights.c \
	core/pack_materials.c core/packed_traverse.c core/light_tree.c
# The scene parser's parts (core/scene_parse.c lists what each does); its gltf statement
# reads glTF files through the C++ shim (core/gltf_load.cpp over tinygltf).
FUZZ_PARSER_SOURCES := core/scene_parse.c core/scene_report.c core/scene_lexer.c core/scene_values.c \
	core/scene_statements.c core/scene_statements_appearance.c core/scene_statements_geometry.c \
	core/scene_builder.c core/scene_validate.c core/affine.c core/scene_gltf.c
FUZZ_GLTF_CXX_SOURCES := core/gltf_load.cpp core/gltf_nodes.cpp
FUZZ_SCENE_SOURCES := tests/fuzz/fuzz_scene_parse.c $(FUZZ_PARSER_SOURCES) core/expression.c core/scene.c \
	core/status.c core/bvh.c $(FUZZ_PACK_SOURCES) core/camera.c $(FUZZ_GLTF_CXX_SOURCES)
FUZZ_EXPRESSION_SOURCES := tests/fuzz/fuzz_expression.c core/expression.c core/status.c
# The loading harnesses run scene_load_assets(), which links the C++ shims (tinyobjloader,
# tinygltf and, for images, OpenImageIO); the libraries themselves are not instrumented.
FUZZ_CXX ?= clang++
FUZZ_ASSET_SOURCES := $(FUZZ_PARSER_SOURCES) core/expression.c core/scene.c core/status.c core/bvh.c \
	$(FUZZ_PACK_SOURCES) core/camera.c core/scene_assets.c core/ply_load.c core/obj_load.cpp core/image_io.cpp \
	core/large_pages.c $(FUZZ_GLTF_CXX_SOURCES)
FUZZ_HARNESSES := $(FUZZ_DIR)/fuzz_scene_parse $(FUZZ_DIR)/fuzz_expression $(FUZZ_DIR)/fuzz_obj_load \
	$(FUZZ_DIR)/fuzz_gltf_load $(FUZZ_DIR)/fuzz_ply_load

# The sources of the harnesses, each compiled once (instrumented) into build-fuzz/objects/
# and shared by the harnesses that use it; a harness links its objects with clang++ and
# the shims' libraries.
FUZZ_OBJECTS := $(FUZZ_DIR)/objects
fuzz_objects = $(patsubst %.cpp,$(FUZZ_OBJECTS)/%.o,$(patsubst %.c,$(FUZZ_OBJECTS)/%.o,$(1)))

$(FUZZ_OBJECTS)/%.o: %.c $(wildcard core/*.h)
	$(say) FUZZCC $<
	@mkdir -p $(dir $@)
	$(Q)$(FUZZ_CC) $(FUZZ_FLAGS) -c $< -o $@

$(FUZZ_OBJECTS)/%.o: %.cpp $(wildcard core/*.h)
	$(say) FUZZCXX $<
	@mkdir -p $(dir $@)
	$(Q)$(FUZZ_CXX) $(subst -std=c11,-std=c++17,$(FUZZ_FLAGS)) $(PKG_CFLAGS) -c $< -o $@

define fuzz_link
	$(say) FUZZLD $@
	$(Q)$(FUZZ_CXX) -fsanitize=fuzzer,address,undefined $^ $(PKG_LIBS) -lm -o $@
endef

$(FUZZ_DIR)/fuzz_scene_parse: $(call fuzz_objects,$(FUZZ_SCENE_SOURCES))
	$(fuzz_link)

$(FUZZ_DIR)/fuzz_expression: $(FUZZ_EXPRESSION_SOURCES) $(wildcard core/*.h)
	$(say) FUZZCC $@
	@mkdir -p $(dir $@)
	$(Q)$(FUZZ_CC) $(FUZZ_FLAGS) $(FUZZ_EXPRESSION_SOURCES) -o $@ -lm

$(FUZZ_DIR)/fuzz_obj_load: $(call fuzz_objects,tests/fuzz/fuzz_obj_load.c $(FUZZ_ASSET_SOURCES))
	$(fuzz_link)

$(FUZZ_DIR)/fuzz_gltf_load: $(call fuzz_objects,tests/fuzz/fuzz_gltf_load.c $(FUZZ_ASSET_SOURCES))
	$(fuzz_link)

$(FUZZ_DIR)/fuzz_ply_load: $(call fuzz_objects,tests/fuzz/fuzz_ply_load.c $(FUZZ_ASSET_SOURCES))
	$(fuzz_link)

fuzz-build: $(FUZZ_HARNESSES)

fuzz: deps
	$(Q)$(MAKE) --no-print-directory fuzz-build
	$(Q)sh tests/fuzz/run.sh $(FUZZ_DIR) $(FUZZ_SECONDS) $(FUZZ_DIR)

fuzz-smoke: deps
	$(Q)mkdir -p $(FUZZ_DIR)/smoke
	$(Q)sh tests/render/test-fuzz-smoke.sh ./$(PROGRAM) $(FUZZ_DIR)/smoke

clean:
	rm -rf build build-san build-fuzz rtspheres

# The dependency files of today's sources only: a source that was removed or renamed leaves
# a .d behind that would name it as a prerequisite and stop the build.
-include $(CORE_OBJ:.o=.d) $(CLI_OBJ:.o=.d) $(UNIT_TESTS:=.d)

# Scale-out on Slurm (tests/slurm/test-slurm.sh, docs/scale-out.md): installs slurmctld,
# slurmd, slurm-client and munge when missing, starts a throw-away single-node cluster in
# a temporary directory, runs scripts/slurm/submit.sh (a job array of shards plus the
# dependent merge), compares the merge with a single-machine render, and stops what it
# started. `make test` runs it too, through tests/render/test-slurm.sh.
.PHONY: test-slurm
test-slurm: deps
	$(Q)$(MAKE) --no-print-directory $(PROGRAM)
	$(Q)sh tests/slurm/test-slurm.sh ./$(PROGRAM)
