#!/usr/bin/env bash
# Runs every ```sh block of docs/getting-started.md as written, in order, in
# one shell (a block may use what an earlier one exported), in a scratch
# folder where build/ is the build tree. The blocks use the simulator's and
# the web server's usual ports (1984, 8080...): so that the test can run
# beside any other, they run in a private network namespace (its own
# loopback) when unshare(1) can make one.
# The README's "Record your first drive" block must be made of lines of
# this page, so that running the page runs it too.
#   run_getting_started.sh docs/getting-started.md BUILD_DIR [TIMEOUT_S] [README.md]
set -euo pipefail
page=$(realpath "$1")
build=$(realpath "$2")
limit=${3:-300}
readme=${4:-}
if [[ -n "$readme" ]]; then
  first_drive=$(awk '/^## Record your first drive/ { found = 1; next }
                     found && /^```sh/ { inside = 1; next }
                     inside && /^```/ { exit }
                     inside' "$readme")
  [[ -n "$first_drive" ]] || { echo "$readme: no first-drive block" >&2; exit 1; }
  while IFS= read -r line; do
    grep -qxF -- "$line" "$page" || { echo "$readme: '$line' is not in $page" >&2; exit 1; }
  done <<<"$first_drive"
fi
work=$(mktemp -d)
group=""
cleanup() {
  [[ -n "$group" ]] && kill -- "-$group" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

awk '/^```sh[[:space:]]*$/ { inside = 1; print "# --- block " ++n; next }
     inside && /^```/ { inside = 0; next }
     inside' "$page" >"$work/blocks.sh"
blocks=$(grep -c '^# --- block' "$work/blocks.sh" || true)
[[ "$blocks" -gt 0 ]] || { echo "no \`\`\`sh block in $page" >&2; exit 1; }

ln -s "$build" "$work/build"
cd "$work"
export GST_REGISTRY="$work/registry.bin" PATH="$build/bin:$PATH"
run=(bash -euo pipefail -x blocks.sh)
if unshare -rn true 2>/dev/null; then
  # Root only inside the namespace: enough to bring its loopback up.
  run=(unshare -rn bash -c 'ip link set lo up 2>/dev/null || ifconfig lo up; exec "$@"' bash "${run[@]}")
else
  echo "run_getting_started: no private network namespace; using the machine's ports" >&2
fi
# A process group of its own, so that background jobs end with it.
setsid timeout --kill-after=5 "$limit" "${run[@]}" &
group=$!
if wait "$group"; then
  echo "docs/getting-started.md: $blocks shell blocks ran"
else
  status=$?
  echo "docs/getting-started.md: the blocks failed (exit $status)" >&2
  exit 1
fi
