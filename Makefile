# shatter — the two commands a new user needs:
#   make run    install dependencies, build (Release), run the default scene
#   make test   install dependencies, build, run every test
BUILD ?= build
JOBS  ?= $(shell nproc)
SCENE ?= scenes/two_cylinders.yaml
THREADS ?= $(shell nproc)

.PHONY: all deps build run test bench clean

all: build

deps:
	bash scripts/install-deps.sh

$(BUILD)/CMakeCache.txt: | deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release

build: deps $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS)

run: build
	$(BUILD)/apps/shatter run $(SCENE) --threads $(THREADS)

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) --timeout 600

bench: build
	bash bench/run_all.sh $(BUILD)

clean:
	rm -rf $(BUILD)
