# carom - GNU make build.
# Targets: all check demo bench bench-quick install uninstall abi-check deps clean
# Every output goes under build/ (SAN=1: build/san/, AddressSanitizer + UBSan).

PREFIX  ?= /usr/local
DESTDIR ?=
CC      ?= cc
SAN     ?= 0

# The one version number is CAROM_VERSION_* in the public header; everything
# else (carom_version(), the file names, carom.pc, the CMake config) derives
# from it.
version_part = $(shell sed -n 's/^.define CAROM_VERSION_$(1) *\([0-9][0-9]*\).*/\1/p' include/carom/carom.h)
VERSION_MAJOR := $(call version_part,MAJOR)
VERSION := $(VERSION_MAJOR).$(call version_part,MINOR).$(call version_part,PATCH)
SONAME  := libcarom.so.$(VERSION_MAJOR)
REALNAME := libcarom.so.$(VERSION)

# Packages `deps` installs on Debian (as root): build, test and install-test needs.
PKGS := pkg-config libccd-dev liblua5.4-dev lua5.4 libcmocka-dev abigail-tools cmake clang libclang-rt-dev

# pkg-config is asked when a recipe first needs the flags, never while the
# Makefile is read: on a fresh machine `deps` installs pkg-config and the .pc
# files first. Each value is computed once per make run ($(eval) replaces the
# lazy definition) and falls back to Debian's flags when a .pc is missing.
once = $(eval $(1) := $(2))$($(1))
pkg  = $(shell pkg-config $(1) $(2) 2>/dev/null || echo '$(3)')
CCD_CFLAGS  = $(call once,CCD_CFLAGS,$(call pkg,--cflags,ccd,))
CCD_LIBS    = $(call once,CCD_LIBS,$(call pkg,--libs,ccd,-lccd))
LUA_CFLAGS  = $(call once,LUA_CFLAGS,$(call pkg,--cflags,lua5.4,-I/usr/include/lua5.4))
LUA_LIBS    = $(call once,LUA_LIBS,$(call pkg,--libs,lua5.4,-llua5.4))
CMOCKA_LIBS = $(call once,CMOCKA_LIBS,$(call pkg,--libs,cmocka,-lcmocka))
# ccd's .pc lists -lm itself: link it once, last
# -pthread: the reference thread pool (lib/threads_posix.c)
LDLIBS_ALL  = $(filter-out -lm,$(CCD_LIBS)) -lm -pthread

# ---- install layout -------------------------------------------------------
# LIBDIR: Debian's multiarch directory where the compiler has one (it is on
# ld.so's, pkg-config's and CMake's search paths for /usr and /usr/local).
MULTIARCH = $(call once,MULTIARCH,$(shell $(CC) -print-multiarch 2>/dev/null))
BINDIR  ?= $(PREFIX)/bin
INCDIR  ?= $(PREFIX)/include
LIBDIR  ?= $(PREFIX)/lib$(if $(MULTIARCH),/$(MULTIARCH))
DOCDIR  ?= $(PREFIX)/share/doc/carom
MANDIR  ?= $(PREFIX)/share/man
CMAKEDIR = $(LIBDIR)/cmake/carom
# The Lua module goes where Lua 5.4 looks: Debian's directory for PREFIX=/usr,
# else $(PREFIX)/lib/lua/5.4 (Lua's own layout, on its default cpath for /usr/local).
LUA_CMOD ?= $(if $(filter /usr,$(PREFIX)),$(call pkg,--variable=INSTALL_CMOD,lua5.4,$(LIBDIR)/lua/5.4),$(PREFIX)/lib/lua/5.4)

# ---- build ----------------------------------------------------------------
WARN    := -std=c99 -Wall -Wextra -Wpedantic -Werror
OPT     ?= -O2 -g
ifeq ($(SAN),1)
BUILD   := build/san
OPT     := -O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=all
SANLD   := -fsanitize=address,undefined
else
BUILD   := build
SANLD   :=
endif
# -ffp-contract=off: no fused multiply-add, so every compiler and flag set
# computes the same bits (tests/determinism.sh checks it)
CFLAGS_ALL = $(WARN) $(OPT) -ffp-contract=off -fPIC -fvisibility=hidden -DCAROM_BUILDING -Iinclude -Ilib $(CCD_CFLAGS)

LIB_SRC := $(wildcard lib/*.c)
LIB_OBJ := $(patsubst lib/%.c,$(BUILD)/obj/%.o,$(LIB_SRC))
STATIC  := $(BUILD)/lib/libcarom.a
# Tests and benchmarks reach internal functions: they link every object as is.
INTERNAL := $(BUILD)/lib/libcarom_internal.a
SHARED  := $(BUILD)/lib/$(REALNAME)
SHARED_LINKS := $(BUILD)/lib/$(SONAME) $(BUILD)/lib/libcarom.so

TEST_SRC  := $(wildcard tests/test_*.c)
TEST_BIN  := $(patsubst tests/%.c,$(BUILD)/tests/%,$(TEST_SRC))
BENCH_SRC := $(wildcard bench/*.c)
BENCH_BIN := $(patsubst bench/%.c,$(BUILD)/bench/%,$(BENCH_SRC))

LUA_MOD   := $(BUILD)/lua/carom.so
RUNNER    := $(BUILD)/carom-run
LUA_SRC   := $(filter-out lua/carom-run.c,$(wildcard lua/*.c))

.PHONY: print-cflags all check check-c check-lua test demo bench bench-quick install uninstall abi-check abi-baseline deps clean

all: $(SHARED) $(SHARED_LINKS) $(STATIC) $(RUNNER) $(LUA_MOD)

$(BUILD)/obj/%.o: lib/%.c $(wildcard lib/*.h) $(wildcard include/carom/*.h) | $(BUILD)/obj
	$(CC) $(CFLAGS_ALL) -c $< -o $@

$(BUILD)/obj $(BUILD)/lib $(BUILD)/tests $(BUILD)/bench $(BUILD)/lua:
	mkdir -p $@

# The installed static library exports only carom_*: the objects linked into
# one, its hidden (internal) symbols made local, so they cannot clash with a
# user's own when linked statically.
$(STATIC): $(LIB_OBJ) | $(BUILD)/lib
	ld -r -o $(BUILD)/obj/carom_all.o $^
	objcopy --localize-hidden $(BUILD)/obj/carom_all.o
	rm -f $@ && ar rcs $@ $(BUILD)/obj/carom_all.o

$(INTERNAL): $(LIB_OBJ) | $(BUILD)/lib
	rm -f $@ && ar rcs $@ $^

$(SHARED): $(LIB_OBJ) lib/carom.map | $(BUILD)/lib
	$(CC) -shared -Wl,-soname,$(SONAME) -Wl,--version-script=lib/carom.map -Wl,--no-undefined \
	    $(SANLD) -o $@ $(LIB_OBJ) $(LDLIBS_ALL)

$(BUILD)/lib/$(SONAME): $(SHARED)
	ln -sf $(REALNAME) $@
$(BUILD)/lib/libcarom.so: $(BUILD)/lib/$(SONAME)
	ln -sf $(SONAME) $@

# Tests link the static library: they reach internal (hidden) functions too.
$(BUILD)/tests/%: tests/%.c $(INTERNAL) $(wildcard tests/*.h) | $(BUILD)/tests
	$(CC) $(CFLAGS_ALL) -Wno-unused-parameter $< -o $@ $(INTERNAL) $(CMOCKA_LIBS) $(LDLIBS_ALL) $(SANLD)

$(BUILD)/bench/%: bench/%.c $(INTERNAL) $(wildcard bench/*.h) | $(BUILD)/bench
	$(CC) $(CFLAGS_ALL) -Wno-unused-function -Ibench $< -o $@ $(INTERNAL) $(LDLIBS_ALL) $(SANLD)

# The Lua module and the runner (the runner links the module in, so it runs
# under the sanitizers without preloading anything into the system lua).
$(LUA_MOD): $(LUA_SRC) $(STATIC) $(wildcard lua/*.h) | $(BUILD)/lua
	$(CC) $(CFLAGS_ALL) $(LUA_CFLAGS) -shared $(LUA_SRC) -o $@ $(STATIC) $(LDLIBS_ALL) $(SANLD)

$(RUNNER): lua/carom-run.c $(LUA_SRC) $(STATIC) $(wildcard lua/*.h) | $(BUILD)/lib
	$(CC) $(CFLAGS_ALL) $(LUA_CFLAGS) -DCAROM_RUNNER_STATIC lua/carom-run.c $(LUA_SRC) -o $@ \
	    $(STATIC) $(LUA_LIBS) $(LDLIBS_ALL) $(SANLD)

# The sanitizer build used to live in build-san/: forward old paths.
build-san/%: FORCE
	@echo "($@ is now build/san/$*)"
	$(MAKE) --no-print-directory SAN=1 build/san/$*

# ---- tests ----------------------------------------------------------------
# Targets that need the dependencies run `deps` first, then make again, so
# that nothing of the build is read before the packages are there.
check: deps
	$(MAKE) --no-print-directory all
	$(MAKE) --no-print-directory check-c
	$(MAKE) --no-print-directory check-lua
	$(MAKE) --no-print-directory check-fuzz-replay
	./tests/determinism.sh
	./tests/install_test.sh
	./tests/fresh_machine_test.sh
	$(MAKE) --no-print-directory SAN=1 all
	$(MAKE) --no-print-directory SAN=1 check-c
	$(MAKE) --no-print-directory SAN=1 check-lua
	$(MAKE) --no-print-directory SAN=1 check-fuzz-replay
	@echo "make check: all tests passed"

test: check

check-c: $(TEST_BIN)
	@set -e; for t in $(TEST_BIN); do echo "== $$t"; CAROM_ROOT=$(CURDIR) ./$$t 2>&1; done
	@echo "== tests/no_circles.sh"; ./tests/no_circles.sh $(BUILD)/obj

# Under SAN=1 the stand-alone lua5.4 loads the instrumented module with the
# ASan runtime preloaded (it must come first); CAROM_LUA says how to start it.
SAN_LUA = env LD_PRELOAD=$$($(CC) -print-file-name=libasan.so) ASAN_OPTIONS=detect_leaks=0 lua5.4
check-lua: $(RUNNER) $(LUA_MOD)
	@set -e; for t in $(wildcard tests/*_test.lua); do echo "== $$t"; \
	    CAROM_LUA="$(if $(filter 1,$(SAN)),$(SAN_LUA),lua5.4)" ./$(RUNNER) --test $$t 2>&1; done

demo: deps
	$(MAKE) --no-print-directory all
	./$(RUNNER) demos/showcase.lua

bench: deps
	$(MAKE) --no-print-directory all $(BENCH_BIN)
	./bench/run.sh

bench-quick: deps
	$(MAKE) --no-print-directory all $(BUILD)/bench/bench_carom
	./bench/run.sh --quick

include fuzz/fuzz.mk

print-cflags:
	@echo $(CFLAGS_ALL)

# ---- install --------------------------------------------------------------
# Every file install writes, so that uninstall removes exactly those.
INSTALLED = $(INCDIR)/carom/carom.h $(INCDIR)/carom/carom_threads.h \
    $(LIBDIR)/$(REALNAME) $(LIBDIR)/$(SONAME) $(LIBDIR)/libcarom.so $(LIBDIR)/libcarom.a \
    $(LIBDIR)/pkgconfig/carom.pc $(CMAKEDIR)/caromConfig.cmake $(CMAKEDIR)/caromConfigVersion.cmake \
    $(LUA_CMOD)/carom.so $(BINDIR)/carom-run $(MANDIR)/man1/carom-run.1 \
    $(DOCDIR)/README.md $(DOCDIR)/lua.md $(addprefix $(DOCDIR)/examples/,$(notdir $(wildcard demos/*.lua)))
# directories that are carom's own (removed by uninstall when empty)
OWN_DIRS = $(INCDIR)/carom $(CMAKEDIR) $(DOCDIR)/examples $(DOCDIR)

# Text files generated for the install prefix (build/install/, rewritten
# whenever the layout variables change).
GEN = build/install
$(GEN)/layout: FORCE
	@mkdir -p $(GEN)
	@echo '$(PREFIX) $(LIBDIR) $(INCDIR) $(VERSION)' > $@.new
	@cmp -s $@.new $@ && rm -f $@.new || mv -f $@.new $@
$(GEN)/carom.pc: carom.pc.in $(GEN)/layout
	sed -e 's|@PREFIX@|$(PREFIX)|' -e 's|@LIBDIR@|$(LIBDIR)|' -e 's|@INCDIR@|$(INCDIR)|' \
	    -e 's|@VERSION@|$(VERSION)|' carom.pc.in > $@
# The CMake files find the library relative to their own place, so a DESTDIR
# tree or a moved prefix works as well.
$(GEN)/caromConfig.cmake: cmake/caromConfig.cmake.in $(GEN)/layout
	sed -e 's|@LIBDIR_FROM_CMAKEDIR@|$(shell realpath -m --relative-to=$(CMAKEDIR) $(LIBDIR))|' \
	    -e 's|@INCDIR_FROM_CMAKEDIR@|$(shell realpath -m --relative-to=$(CMAKEDIR) $(INCDIR))|' \
	    -e 's|@REALNAME@|$(REALNAME)|' -e 's|@SONAME@|$(SONAME)|' $< > $@
$(GEN)/caromConfigVersion.cmake: cmake/caromConfigVersion.cmake.in $(GEN)/layout
	sed -e 's|@VERSION@|$(VERSION)|' $< > $@

install: all $(GEN)/carom.pc $(GEN)/caromConfig.cmake $(GEN)/caromConfigVersion.cmake
	install -d $(DESTDIR)$(INCDIR)/carom $(DESTDIR)$(LIBDIR)/pkgconfig $(DESTDIR)$(CMAKEDIR) \
	    $(DESTDIR)$(BINDIR) $(DESTDIR)$(LUA_CMOD) $(DESTDIR)$(MANDIR)/man1 $(DESTDIR)$(DOCDIR)/examples
	install -m 644 include/carom/carom.h include/carom/carom_threads.h $(DESTDIR)$(INCDIR)/carom/
	install -m 755 $(SHARED) $(DESTDIR)$(LIBDIR)/
	ln -sf $(REALNAME) $(DESTDIR)$(LIBDIR)/$(SONAME)
	ln -sf $(SONAME) $(DESTDIR)$(LIBDIR)/libcarom.so
	install -m 644 $(STATIC) $(DESTDIR)$(LIBDIR)/
	install -m 644 $(GEN)/carom.pc $(DESTDIR)$(LIBDIR)/pkgconfig/
	install -m 644 $(GEN)/caromConfig.cmake $(GEN)/caromConfigVersion.cmake $(DESTDIR)$(CMAKEDIR)/
	install -m 755 $(LUA_MOD) $(DESTDIR)$(LUA_CMOD)/carom.so
	install -m 755 $(RUNNER) $(DESTDIR)$(BINDIR)/carom-run
	install -m 644 docs/carom-run.1 $(DESTDIR)$(MANDIR)/man1/
	install -m 644 README.md docs/lua.md $(DESTDIR)$(DOCDIR)/
	install -m 644 demos/*.lua $(DESTDIR)$(DOCDIR)/examples/
	@# ld.so finds a new library only after ldconfig rebuilds its cache
	@if [ -z "$(DESTDIR)" ] && [ "$$(id -u)" = 0 ] && ldconfig -v -N 2>/dev/null | grep -q '^$(LIBDIR):'; then \
	    echo "install: ldconfig"; ldconfig; \
	elif [ -z "$(DESTDIR)" ] && ! ldconfig -v -N 2>/dev/null | grep -q '^$(LIBDIR):'; then \
	    echo "install: $(LIBDIR) is not on ld.so's path: run programs with LD_LIBRARY_PATH=$(LIBDIR)"; \
	fi

uninstall:
	rm -f $(addprefix $(DESTDIR),$(INSTALLED))
	@for d in $(addprefix $(DESTDIR),$(OWN_DIRS)); do [ ! -d "$$d" ] || rmdir "$$d" 2>/dev/null || true; done
	@if [ -z "$(DESTDIR)" ] && [ "$$(id -u)" = 0 ] && ldconfig -v -N 2>/dev/null | grep -q '^$(LIBDIR):'; then ldconfig; fi

# ---- ABI ------------------------------------------------------------------
abi-check: deps
	$(MAKE) --no-print-directory $(SHARED)
	@test -f abi/libcarom.abi || { echo "abi-check: abi/libcarom.abi is missing"; exit 1; }
	abidiff --no-added-syms --suppressions abi/suppressions.abignore --headers-dir2 include/carom \
	    abi/libcarom.abi $(SHARED) && echo "abi-check: ABI matches abi/libcarom.abi"

abi-baseline: $(SHARED)
	abidw --headers-dir include/carom --out-file abi/libcarom.abi $(SHARED)

# ---- set-up ---------------------------------------------------------------
deps:
	@missing=""; \
	for c in pkg-config abidw cmake lua5.4 clang; do command -v $$c >/dev/null 2>&1 || missing=1; done; \
	for p in ccd lua5.4 cmocka; do pkg-config --exists $$p 2>/dev/null || missing=1; done; \
	if [ -n "$$missing" ]; then \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	    echo "deps: installing $(PKGS)"; \
	    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $(PKGS) >/dev/null || exit 1; \
	  else \
	    echo "deps: missing build dependencies. On Debian/Ubuntu run as root:"; \
	    echo "    apt-get update && apt-get install -y $(PKGS)"; \
	    echo "(elsewhere install libccd (double precision), Lua 5.4 with headers, cmocka, pkg-config, libabigail, cmake, clang and libFuzzer)"; \
	    exit 1; \
	  fi; \
	fi

clean:
	rm -rf build build-san bench/out bench/peers/build lib/libcarom.so* lib/libcarom.a  # all but build: left by older checkouts

FORCE:
