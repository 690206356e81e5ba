# shatter — the two commands a new user needs:
#   make run    install dependencies, build (Release), run the default scene
#   make test   install dependencies, build, run every test
# and: make bench (build and run the benchmarks; results in bench/results/)
BUILD   ?= build
JOBS    ?= $(shell nproc)
SCENE   ?= scenes/two_cylinders.yaml
THREADS ?= $(shell nproc)
CMAKE_FLAGS ?= -DCMAKE_BUILD_TYPE=Release

.PHONY: all deps configure build run test bench clean

all: build

deps:
	bash scripts/install-deps.sh

# Benchmarks are built by `make bench` only: they are not needed by the tests
# and the CGAL one is slow to compile.
configure: deps
	cmake -S . -B $(BUILD) $(CMAKE_FLAGS) -DSHATTER_BUILD_BENCH=OFF

build: configure
	cmake --build $(BUILD) -j $(JOBS)

run: configure
	cmake --build $(BUILD) -j $(JOBS) --target shatter
	$(BUILD)/apps/shatter run $(SCENE) --threads $(THREADS)

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) --timeout 900

bench: deps
	cmake -S . -B $(BUILD) $(CMAKE_FLAGS) -DSHATTER_BUILD_BENCH=ON
	cmake --build $(BUILD) -j $(JOBS)
	bash bench/run_all.sh $(BUILD)

clean:
	rm -rf $(BUILD)
