#!/usr/bin/env bash
# Figure 10 on a Slurm cluster: an array of N shards, then a merge job that runs when they
# have all finished. Usage: scripts/slurm/fig10.sh OUT N [flags of simlod experiment fig10]
# Add --wait before OUT's flags by setting SBATCH_WAIT=1 to block until the merge is done.
set -euo pipefail
OUT=${1:?usage: fig10.sh OUT N [flags]}
N=${2:?usage: fig10.sh OUT N [flags]}
shift 2
cd "$(dirname "$0")/../.."
SIMLOD=${SIMLOD:-target/release/simlod}
export SIMLOD
ARRAY=$(sbatch --parsable --chdir="$PWD" --array=1-"$N" scripts/slurm/fig10.sbatch "$OUT" "$@")
echo "submitted the shards: job $ARRAY"
WAIT=()
[ -n "${SBATCH_WAIT:-}" ] && WAIT=(--wait)
SHARDS=()
for k in $(seq 1 "$N"); do SHARDS+=("$OUT/shard-$k"); done
sbatch "${WAIT[@]}" --parsable --chdir="$PWD" --dependency=afterok:"$ARRAY" --job-name=simlod-fig10-merge \
    --output="slurm-%j-merge.out" --wrap="$SIMLOD experiment merge ${SHARDS[*]} --out $OUT"
