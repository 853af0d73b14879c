#!/bin/bash
# Generates a dataset on a SLURM cluster: SHARDS array tasks, then a merge job that runs once
# all of them have succeeded.
#   deploy/slurm/submit.sh OUT SHARDS [lfgen arguments...]
#   deploy/slurm/submit.sh /shared/lfgen 8 --scenes 110
# Prints the array job id and the merge job id, one per line. LFGEN (default: lfgen on PATH)
# names the binary, LFGEN_CPUS (default 16) the cores per task; other sbatch options go in
# the SBATCH_* environment variables sbatch reads itself (SBATCH_PARTITION, SBATCH_ACCOUNT,
# SBATCH_TIMELIMIT, ...).
set -euo pipefail
if [ $# -lt 2 ]; then
    echo "usage: $0 OUT SHARDS [lfgen arguments...]" >&2
    exit 2
fi
out=$1 shards=$2
shift 2
here=$(cd "$(dirname "$0")" && pwd)
export LFGEN_OUT=$out LFGEN=${LFGEN:-lfgen}
array=$(sbatch --parsable --export=ALL --array="0-$((shards - 1))" \
    --cpus-per-task="${LFGEN_CPUS:-16}" "$here/lfgen-array.sbatch" "$@")
array=${array%%;*}
merge=$(sbatch --parsable --export=ALL --dependency="afterok:$array" "$here/lfgen-merge.sbatch")
echo "$array"
echo "${merge%%;*}"
