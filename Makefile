# Entry points; see README.md.  `make test` and `make example` are the two commands.
JOBS ?= $(shell nproc)
CMAKE_ARGS = -DPython3_EXECUTABLE=/usr/bin/python3

.PHONY: deps build build-debug test test-unit example bench validate clean

deps:
	./scripts/install-deps.sh

build: deps
	cmake -S . -B build -DCMAKE_BUILD_TYPE=Release $(CMAKE_ARGS) >/dev/null
	cmake --build build -j $(JOBS)

build-debug: deps
	cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DHB_SANITIZE=ON -DHB_BUILD_BENCH=OFF $(CMAKE_ARGS) >/dev/null
	cmake --build build-asan -j $(JOBS)

# Unit tests under ASan/UBSan (Debug), then unit + physics checks on the Release build.
test: build build-debug
	cd build-asan && ctest -L unit -j $(JOBS) --output-on-failure
	cd build && ctest -j $(JOBS) --output-on-failure

# the example needs only the program (not the tests, benchmarks or the Python module)
example: deps
	cmake -S . -B build -DCMAKE_BUILD_TYPE=Release $(CMAKE_ARGS) >/dev/null
	cmake --build build -j $(JOBS) --target hardbody
	./build/apps/hardbody/hardbody run examples/hard-spheres.toml --out run-hard-spheres --overwrite

bench: build
	./scripts/bench.sh

clean:
	rm -rf build build-asan
