# fuzz/fuzz.mk - libFuzzer harnesses (included by the Makefile).
#   make fuzz [FUZZ_SECONDS=60] [FUZZ_JOBS=1]   build with clang and run each harness
#   make fuzz-smoke                              each for 300 inputs from seed 1 (CI: the same on every machine)
#   make check-fuzz-replay                       the seed corpus and every past crash through
#                                                the harnesses, built with $(CC) (part of make check)
# Harnesses: api (C call sequences), scene (random scenes), lua (random
# scripts), snapshot (the snapshot reader). Seeds in fuzz/corpus/<name>/,
# inputs that once crashed in fuzz/regressions/<name>/ (replayed by make check).

FUZZ_CC      ?= clang
FUZZ_SECONDS ?= 60
FUZZ_SMOKE   ?= 15
# A fixed seed and a fixed number of inputs make the smoke run the same on every
# machine (a time limit alone would let a faster CI machine reach other inputs).
FUZZ_SMOKE_RUNS ?= 300
FUZZ_LIMIT    = -max_total_time=$(FUZZ_SECONDS)
FUZZ_NAMES   := api scene lua snapshot
FUZZ_DIR     := build/fuzz-clang
# the working corpus (grown inputs; kept between runs, out of git)
FUZZ_CORPUS  ?= $(FUZZ_DIR)/corpus
FUZZ_SAN     := -fsanitize=address,undefined -fno-sanitize-recover=all
FUZZ_CFLAGS   = -std=c99 -Wall -Wextra -Werror -g -O1 -fno-omit-frame-pointer -ffp-contract=off $(FUZZ_SAN) \
                -DCAROM_BUILDING -Iinclude -Ilib -Ifuzz $(CCD_CFLAGS) $(LUA_CFLAGS)
FUZZ_LIB_OBJ := $(patsubst lib/%.c,$(FUZZ_DIR)/lib/%.o,$(LIB_SRC))
FUZZ_LUA_OBJ := $(patsubst lua/%.c,$(FUZZ_DIR)/lua/%.o,$(LUA_SRC))
FUZZ_BIN     := $(patsubst %,$(FUZZ_DIR)/fuzz_%,$(FUZZ_NAMES))

.PHONY: fuzz fuzz-build fuzz-smoke check-fuzz-replay
# The objects are intermediates of the fuzz_% pattern rule: without this make
# deletes all of them after linking and rebuilds every one on the next run.
.SECONDARY: $(FUZZ_LIB_OBJ) $(FUZZ_LUA_OBJ)

$(FUZZ_DIR)/lib/%.o: lib/%.c $(wildcard lib/*.h) $(wildcard include/carom/*.h)
	@mkdir -p $(dir $@)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -fsanitize=fuzzer-no-link -c $< -o $@

$(FUZZ_DIR)/lua/%.o: lua/%.c $(wildcard lua/*.h) $(wildcard include/carom/*.h)
	@mkdir -p $(dir $@)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -fsanitize=fuzzer-no-link -c $< -o $@

$(FUZZ_DIR)/fuzz_%: fuzz/fuzz_%.c $(FUZZ_LIB_OBJ) $(FUZZ_LUA_OBJ) $(wildcard fuzz/*.h)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -fsanitize=fuzzer $< -o $@ $(FUZZ_LIB_OBJ) \
	    $(if $(filter fuzz/fuzz_lua.c,$<),$(FUZZ_LUA_OBJ) $(LUA_LIBS)) $(LDLIBS_ALL)

fuzz-build: deps
	@command -v $(FUZZ_CC) >/dev/null || { echo "make fuzz needs clang and libFuzzer: apt-get install clang libclang-rt-dev"; exit 1; }
	$(MAKE) --no-print-directory $(FUZZ_BIN)

# Each harness runs FUZZ_SECONDS on a working corpus seeded from fuzz/corpus
# (new inputs stay in $(FUZZ_CORPUS)); a crash stops it with the input saved in
# build/fuzz-clang/artifacts/: copy it to fuzz/regressions/<name>/ once fixed.
fuzz: fuzz-build
	@set -e; for n in $(FUZZ_NAMES); do \
	    mkdir -p $(FUZZ_CORPUS)/$$n $(FUZZ_DIR)/artifacts/$$n fuzz/corpus/$$n; \
	    echo "== fuzz_$$n for $(FUZZ_SECONDS) s"; \
	    log=$(FUZZ_DIR)/fuzz_$$n.log; \
	    if ! ./$(FUZZ_DIR)/fuzz_$$n $(FUZZ_LIMIT) -timeout=20 -rss_limit_mb=2048 -max_len=65536 \
	        -print_final_stats=1 -artifact_prefix=$(FUZZ_DIR)/artifacts/$$n/ \
	        $(FUZZ_CORPUS)/$$n fuzz/corpus/$$n > $$log 2>&1; then \
	        tail -40 $$log; echo "fuzz_$$n: crash, input saved in $(FUZZ_DIR)/artifacts/$$n/"; exit 1; fi; \
	    grep -E "^#[0-9]+.*(DONE|cov:)" $$log | tail -1; grep -E "stat::number_of_executed_units|stat::peak_rss_mb" $$log; \
	done; echo "make fuzz: no crash"

# from the seeds alone, in a corpus of its own (the working corpus is kept)
fuzz-smoke:
	rm -rf $(FUZZ_DIR)/smoke-corpus
	$(MAKE) --no-print-directory fuzz FUZZ_SECONDS=$(FUZZ_SMOKE) FUZZ_CORPUS=$(FUZZ_DIR)/smoke-corpus \
	    FUZZ_LIMIT='-seed=1 -runs=$(FUZZ_SMOKE_RUNS) -max_total_time=600'

# The harnesses as plain programs over files (fuzz/replay.c is their main).
$(BUILD)/fuzz/replay_%: fuzz/fuzz_%.c fuzz/replay.c $(STATIC) $(wildcard fuzz/*.h) $(LUA_SRC)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) -Ifuzz $(LUA_CFLAGS) fuzz/replay.c $< -o $@ \
	    $(if $(filter fuzz/fuzz_lua.c,$<),$(LUA_SRC)) $(STATIC) $(if $(filter fuzz/fuzz_lua.c,$<),$(LUA_LIBS)) \
	    $(LDLIBS_ALL) $(SANLD)

check-fuzz-replay: $(patsubst %,$(BUILD)/fuzz/replay_%,$(FUZZ_NAMES))
	@set -e; for n in $(FUZZ_NAMES); do \
	    echo "== replay fuzz_$$n"; ./$(BUILD)/fuzz/replay_$$n fuzz/corpus/$$n fuzz/regressions/$$n; done
