#!/usr/bin/env bash
# Compile time of every translation unit, for the Release and the sanitizer builds of `make test`
# (the CI limit is 90 minutes for everything; session 4 found the sanitizer build alone past it).
#
# Usage: scripts/build-times.sh [--top N] [--out FILE]
#   Builds from scratch in build-times-release/ and build-times-asan/ (with -j $(nproc)), timing
#   each compiler call through a launcher, and writes a Markdown table (default
#   docs/build-times.md): wall time of each build, summed compile time, the N slowest units.
# Compile times depend on the machine and its load: run it on a quiet machine.
set -euo pipefail
cd "$(dirname "$0")/.."
top=15
out=docs/build-times.md
while [ $# -gt 0 ]; do
  case "$1" in
    --top) top=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    *) echo "build-times.sh: unknown argument '$1' (usage: [--top N] [--out FILE])" >&2; exit 2 ;;
  esac
done
jobs=$(nproc)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
launcher=$tmp/timecc
cat > "$launcher" <<'EOF'
#!/usr/bin/env bash
# Runs one compiler call and appends "<seconds> <object file>" to $HB_TIMECC_LOG.
start=$(date +%s.%N)
status=0
"$@" || status=$?
end=$(date +%s.%N)
obj=""; prev=""
for a in "$@"; do [ "$prev" = "-o" ] && obj=$a; prev=$a; done
awk -v a="$start" -v b="$end" -v o="$obj" 'BEGIN {printf "%.3f %s\n", b - a, o}' >> "$HB_TIMECC_LOG"
exit $status
EOF
chmod +x "$launcher"

# build NAME DIR CMAKE_ARGS...: prints the build's wall seconds; per-unit log in $tmp/NAME.log
build() {
  local name=$1 dir=$2; shift 2
  rm -rf "$dir"
  cmake -S . -B "$dir" -DPython3_EXECUTABLE=/usr/bin/python3 -DCMAKE_CXX_COMPILER_LAUNCHER="$launcher" \
        "$@" > /dev/null
  local t0 t1
  t0=$(date +%s.%N)
  HB_TIMECC_LOG=$tmp/$name.log cmake --build "$dir" -j "$jobs" > "$tmp/$name.out" 2>&1 ||
    { tail -20 "$tmp/$name.out" >&2; echo "build-times.sh: the $name build failed" >&2; exit 1; }
  t1=$(date +%s.%N)
  awk -v a="$t0" -v b="$t1" 'BEGIN {printf "%.1f\n", b - a}'
}

./scripts/install-deps.sh
rel_wall=$(build release build-times-release -DCMAKE_BUILD_TYPE=Release)
asan_wall=$(build asan build-times-asan -DCMAKE_BUILD_TYPE=Debug -DHB_SANITIZE=ON -DHB_BUILD_BENCH=OFF)

{
  echo "# Build times"
  echo
  echo "Written by \`scripts/build-times.sh\` on $(date -u +%Y-%m-%d) from commit" \
       "$(git rev-parse --short HEAD)$(git diff --quiet HEAD -- src tests apps python bench CMakeLists.txt || echo ' (with uncommitted changes)'),"
  echo "$jobs cores ($(uname -m)), $(c++ --version | head -1)."
  echo "Each build starts from an empty directory; the per-unit times are wall seconds of one"
  echo "compiler call while the other calls of the parallel build ran beside it."
  echo
  echo "| build | wall (s) | compile, summed (s) | units |"
  echo "|---|---:|---:|---:|"
  for name in release asan; do
    wall=$rel_wall; [ $name = asan ] && wall=$asan_wall
    awk -v n="$name" -v w="$wall" '{s += $1; k++} END {printf "| %s | %.0f | %.0f | %d |\n", n, w, s, k}' "$tmp/$name.log"
  done
  for name in release asan; do
    echo
    echo "## Slowest $top units: $name"
    echo
    echo "| seconds | object |"
    echo "|---:|---|"
    sort -rn "$tmp/$name.log" | head -n "$top" | awk '{printf "| %.1f | %s |\n", $1, $2}'
  done
} > "$out"
echo "build-times.sh: wrote $out (release build ${rel_wall%.*} s, sanitizer build ${asan_wall%.*} s)"
