# rtspheres: headless batch ray tracer.
#
# Targets
#   all      (default) build ./rtspheres
#   demo     install missing packages, build, render scenes/three-balls.txt to demo.png
#   test     install missing packages, build, run every test (unit, render, analytic)
#   bench    build with release flags and time the benchmark scenes (not a test)
#   golden   re-render the golden images in golden/ (never run by the tests; say why in
#            the commit when you commit new ones)
#   deps     install the Debian packages listed in .ci/debian-packages that are missing
#   clean    remove build products
#
# Knobs
#   V=1        show the commands
#   SAN=1      build with AddressSanitizer + UndefinedBehaviorSanitizer (into build-san/)
#   CFLAGS, CXXFLAGS, LDFLAGS   yours: appended after ours, never replacing them
#   CC, CXX    compilers (default cc, c++)

all: rtspheres
.PHONY: all demo test bench golden deps clean unit-tests

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
PKGS := epoxy egl OpenImageIO tinyobjloader cglm
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
SHADERS := $(wildcard glsl/*) core/packed_layout.h

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

# The shaders are embedded with the assembler's .incbin, so the binary runs from anywhere.
$(BUILD)/%.o: %.S $(SHADERS)
	$(say) EMBED $<
	@mkdir -p $(dir $@)
	$(Q)$(CC) -Wa,-I. -c $< -o $@

$(LIBRARY): $(CORE_OBJ)
	$(say) AR $@
	$(Q)rm -f $@ && ar rcs $@ $^

$(PROGRAM): $(CLI_OBJ) $(LIBRARY)
	$(say) LINK $@
	$(Q)$(CXX) $(OUR_LDFLAGS) $(LDFLAGS) $(CLI_OBJ) $(LIBRARY) $(PKG_LIBS) -lm -o $@

$(BUILD)/tests/%: tests/unit/%.c $(LIBRARY)
	$(say) TEST $@
	@mkdir -p $(dir $@)
	$(Q)$(CC) $(OUR_CFLAGS) $(PKG_CFLAGS) $(CFLAGS) $< -o $@ $(OUR_LDFLAGS) $(LDFLAGS) \
		$(LIBRARY) $(PKG_LIBS) $(CMOCKA_LIBS) -lstdc++ -lm

unit-tests: $(UNIT_TESTS)

# Installs what .ci/debian-packages lists and dpkg says is missing (sudo when not root).
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
deps:
	@missing=$$(grep -v '^\s*#' .ci/debian-packages | while read -r p; do \
		[ -n "$$p" ] || continue; \
		dpkg-query -W -f='$${Status}\n' "$$p" 2>/dev/null | grep -q 'install ok installed' || echo "$$p"; \
	done | tr '\n' ' '); \
	if [ -n "$$missing" ]; then \
		echo "deps: installing missing Debian packages: $$missing"; \
		$(SUDO) apt-get update -q && \
		$(SUDO) env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends $$missing; \
	fi

demo: deps
	$(Q)$(MAKE) --no-print-directory all
	./$(PROGRAM) render scenes/three-balls.txt -o demo.png
	@echo "demo: wrote demo.png"

test: deps
	$(Q)$(MAKE) --no-print-directory $(PROGRAM) unit-tests
	$(Q)sh tests/run.sh $(BUILD) ./$(PROGRAM)

bench: deps
	$(Q)$(MAKE) --no-print-directory all
	$(Q)sh tests/bench/run.sh ./$(PROGRAM)

golden: all
	$(Q)sh tests/render/make-golden.sh ./$(PROGRAM)

clean:
	rm -rf build build-san rtspheres

-include $(shell find build build-san -name '*.d' 2>/dev/null)
