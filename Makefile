# carom - GNU make build. Targets: all check demo bench install abi-check deps clean
# SAN=1 builds into build-san/ with AddressSanitizer and UBSan.

PREFIX  ?= /usr/local
DESTDIR ?=
CC      ?= cc
SAN     ?= 0

VERSION := 1.0.0
SONAME  := libcarom.so.1

PKGS      := libccd-dev liblua5.4-dev lua5.4 libcmocka-dev pkg-config abigail-tools
PKGCONFIG := $(shell command -v pkg-config 2>/dev/null)
CCD_CFLAGS  := $(if $(PKGCONFIG),$(shell pkg-config --cflags ccd 2>/dev/null))
CCD_LIBS    := $(if $(PKGCONFIG),$(shell pkg-config --libs ccd 2>/dev/null),-lccd)
LUA_CFLAGS  := $(if $(PKGCONFIG),$(shell pkg-config --cflags lua5.4 2>/dev/null))
LUA_LIBS    := $(if $(PKGCONFIG),$(shell pkg-config --libs lua5.4 2>/dev/null),-llua5.4)
CMOCKA_LIBS := $(if $(PKGCONFIG),$(shell pkg-config --libs cmocka 2>/dev/null),-lcmocka)
# The Lua module goes where Lua 5.4 looks: Debian's directory for PREFIX=/usr,
# else $(PREFIX)/lib/lua/5.4 (on Lua's default cpath for /usr/local).
ifeq ($(PREFIX),/usr)
LUA_CMOD := $(shell pkg-config --variable=INSTALL_CMOD lua5.4 2>/dev/null)
endif
ifeq ($(LUA_CMOD),)
LUA_CMOD := $(PREFIX)/lib/lua/5.4
endif

WARN    := -std=c99 -Wall -Wextra -Wpedantic -Werror
OPT     ?= -O2 -g
ifeq ($(SAN),1)
BUILD   := build-san
OPT     := -O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=all
SANLD   := -fsanitize=address,undefined
else
BUILD   := build
SANLD   :=
endif
CFLAGS_ALL := $(WARN) $(OPT) -fPIC -fvisibility=hidden -DCAROM_BUILDING -Iinclude -Ilib $(CCD_CFLAGS)
LDLIBS_ALL := $(CCD_LIBS) -lm

LIB_SRC := $(wildcard lib/*.c)
LIB_OBJ := $(patsubst lib/%.c,$(BUILD)/lib/%.o,$(LIB_SRC))
STATIC  := $(BUILD)/libcarom.a
ifeq ($(SAN),1)
SHARED  := $(BUILD)/$(SONAME)
else
SHARED  := lib/$(SONAME)
endif

TEST_SRC  := $(wildcard tests/test_*.c)
TEST_BIN  := $(patsubst tests/%.c,$(BUILD)/tests/%,$(TEST_SRC))
BENCH_SRC := $(wildcard bench/*.c)
BENCH_BIN := $(patsubst bench/%.c,$(BUILD)/bench/%,$(BENCH_SRC))

LUA_MOD   := $(BUILD)/lua/carom.so
RUNNER    := $(BUILD)/carom-run
LUA_SRC   := $(filter-out lua/carom-run.c,$(wildcard lua/*.c))

.PHONY: all check check-c check-san check-lua test demo bench install abi-check abi-baseline deps clean

all: $(SHARED) $(if $(filter 1,$(SAN)),,lib/libcarom.so lib/libcarom.a) $(if $(wildcard lua/carom-run.c),$(RUNNER) $(LUA_MOD))

$(BUILD)/lib/%.o: lib/%.c $(wildcard lib/*.h) $(wildcard include/carom/*.h) | $(BUILD)/lib
	$(CC) $(CFLAGS_ALL) -c $< -o $@

$(BUILD)/lib $(BUILD)/tests $(BUILD)/bench $(BUILD)/lua:
	mkdir -p $@

$(STATIC): $(LIB_OBJ)
	rm -f $@ && ar rcs $@ $^

lib/libcarom.a: $(STATIC)
	cp $< $@

$(SHARED): $(LIB_OBJ) lib/carom.map
	$(CC) -shared -Wl,-soname,$(SONAME) -Wl,--version-script=lib/carom.map -Wl,--no-undefined \
	    $(SANLD) -o $@ $(LIB_OBJ) $(LDLIBS_ALL)

lib/libcarom.so: $(SHARED)
	ln -sf $(SONAME) $@

# Tests link the static library: they reach internal (hidden) functions too.
$(BUILD)/tests/%: tests/%.c $(STATIC) $(wildcard tests/*.h) | $(BUILD)/tests
	$(CC) $(CFLAGS_ALL) -Wno-unused-parameter $< -o $@ $(STATIC) $(CMOCKA_LIBS) $(LDLIBS_ALL) $(SANLD)

$(BUILD)/bench/%: bench/%.c $(STATIC) $(wildcard bench/*.h) | $(BUILD)/bench
	$(CC) $(CFLAGS_ALL) -Wno-unused-function -Ibench $< -o $@ $(STATIC) $(LDLIBS_ALL) $(SANLD)

# The Lua module and the runner (the runner links the module in, so it runs
# under the sanitizers without preloading anything into the system lua).
$(LUA_MOD): $(LUA_SRC) $(STATIC) $(wildcard lua/*.h) | $(BUILD)/lua
	$(CC) $(CFLAGS_ALL) $(LUA_CFLAGS) -shared $(LUA_SRC) -o $@ $(STATIC) $(LDLIBS_ALL) $(SANLD)

$(RUNNER): lua/carom-run.c $(LUA_SRC) $(STATIC) $(wildcard lua/*.h)
	$(CC) $(CFLAGS_ALL) $(LUA_CFLAGS) -DCAROM_RUNNER_STATIC lua/carom-run.c $(LUA_SRC) -o $@ \
	    $(STATIC) $(LUA_LIBS) $(LDLIBS_ALL) $(SANLD)

# ---- tests ----------------------------------------------------------------
check: deps
	$(MAKE) --no-print-directory all
	$(MAKE) --no-print-directory check-c
	$(MAKE) --no-print-directory check-lua
	./tests/install_test.sh
	$(MAKE) --no-print-directory SAN=1 check-c
	$(MAKE) --no-print-directory SAN=1 check-lua
	@echo "make check: all tests passed"

test: check

check-c: $(TEST_BIN)
	@set -e; for t in $(TEST_BIN); do echo "== $$t"; CAROM_ROOT=$(CURDIR) ./$$t 2>&1; done

check-lua: $(if $(wildcard lua/carom-run.c),$(RUNNER))
	@set -e; for t in $(wildcard tests/*_test.lua); do echo "== $$t"; \
	    $(if $(wildcard lua/carom-run.c),./$(RUNNER) --test $$t 2>&1,echo skipped); done

demo: deps all
	./$(RUNNER) demos/showcase.lua

bench: deps all $(BENCH_BIN)
	./bench/run.sh

# ---- install --------------------------------------------------------------
install: all
	install -d $(DESTDIR)$(PREFIX)/include/carom $(DESTDIR)$(PREFIX)/lib/pkgconfig $(DESTDIR)$(PREFIX)/bin
	install -m 644 include/carom/*.h $(DESTDIR)$(PREFIX)/include/carom/
	install -m 755 $(SHARED) $(DESTDIR)$(PREFIX)/lib/
	ln -sf $(SONAME) $(DESTDIR)$(PREFIX)/lib/libcarom.so
	install -m 644 $(STATIC) $(DESTDIR)$(PREFIX)/lib/libcarom.a
	sed -e 's|@PREFIX@|$(PREFIX)|' -e 's|@VERSION@|$(VERSION)|' carom.pc.in > $(DESTDIR)$(PREFIX)/lib/pkgconfig/carom.pc
	if [ -f $(RUNNER) ]; then install -m 755 $(RUNNER) $(DESTDIR)$(PREFIX)/bin/carom-run; \
	    install -d $(DESTDIR)$(LUA_CMOD); install -m 755 $(LUA_MOD) $(DESTDIR)$(LUA_CMOD)/carom.so; fi

# ---- ABI ------------------------------------------------------------------
abi-check: deps $(SHARED)
	@test -f abi/libcarom.abi || { echo "abi-check: abi/libcarom.abi is missing"; exit 1; }
	abidiff --no-added-syms --suppressions abi/suppressions.abignore --headers-dir2 include/carom \
	    abi/libcarom.abi $(SHARED) && echo "abi-check: ABI matches abi/libcarom.abi"

abi-baseline: $(SHARED)
	abidw --headers-dir include/carom --out-file abi/libcarom.abi $(SHARED)

# ---- set-up ---------------------------------------------------------------
deps:
	@missing=""; \
	for p in ccd lua5.4 cmocka; do pkg-config --exists $$p 2>/dev/null || missing=1; done; \
	command -v abidw >/dev/null 2>&1 || missing=1; \
	command -v pkg-config >/dev/null 2>&1 || missing=1; \
	if [ -n "$$missing" ]; then \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	    echo "deps: installing $(PKGS)"; \
	    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $(PKGS) >/dev/null || exit 1; \
	  else \
	    echo "deps: missing build dependencies. On Debian/Ubuntu run as root:"; \
	    echo "    apt-get update && apt-get install -y $(PKGS)"; \
	    echo "(elsewhere install libccd (double precision), Lua 5.4 with headers, cmocka, pkg-config and libabigail)"; \
	    exit 1; \
	  fi; \
	fi

clean:
	rm -rf build build-san lib/libcarom.so* lib/libcarom.a bench/out
