# Sourced first by the measuring scripts (trade.sh, texcells_truth.sh, wind.sh, continuous_lod.sh)
# with the folders of ../shared/data they read: `source "$(dirname "$0")/measure_env.sh" nc models`.
# Goes to the repository root ($root), runs wgpu on Vulkan (lavapipe here) without backtraces,
# sets $shared, and stops with a message naming the script if a folder is missing.
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
export WGPU_BACKEND="${WGPU_BACKEND:-vulkan}"
unset RUST_BACKTRACE
shared="$root/../shared/data"
for folder in "$@"; do
    [[ -d "$shared/$folder" ]] || {
        echo "$(basename "$0"): $shared/$folder is missing (needs ${*/%//} in $shared)" >&2
        exit 1
    }
done
