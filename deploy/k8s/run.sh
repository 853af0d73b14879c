#!/bin/sh
# Generates the dataset on the cluster of the current kubectl context: the volume (only where
# no claim `lfgen-data` exists yet, so one made by hand is kept), the shard Job, then the merge
# Job once every shard has completed. Each wait ends as soon as its Job fails, printing the
# Job's state and its last log lines, with exit code 1 (`kubectl wait --for=condition=complete`
# alone would wait out its whole timeout on a failed Job). Running it again resumes: the old
# Jobs are deleted first and the shards keep every scene they already published (--resume).
#   deploy/k8s/run.sh
# KUBECTL names the kubectl command (default: kubectl), LFGEN_POLL the seconds between two
# looks at a Job (default: 10).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
kubectl=${KUBECTL:-kubectl}

# Returns once Job $1 is complete; exits 1 as soon as it has failed.
wait_for() {
    while :; do
        state=$($kubectl get "job/$1" -o 'jsonpath={.status.conditions[?(@.status=="True")].type}')
        case " $state " in
        *" Complete "*) return 0 ;;
        *" Failed "*)
            echo "run.sh: job/$1 failed" >&2
            $kubectl describe "job/$1" >&2 || true
            $kubectl logs "job/$1" --tail=20 >&2 || true
            exit 1
            ;;
        esac
        sleep "${LFGEN_POLL:-10}"
    done
}

$kubectl get pvc lfgen-data >/dev/null 2>&1 || $kubectl apply -f "$here/volume.yaml"
$kubectl delete job lfgen-shards lfgen-merge --ignore-not-found --cascade=foreground
$kubectl apply -f "$here/shards-job.yaml"
wait_for lfgen-shards
$kubectl apply -f "$here/merge-job.yaml"
wait_for lfgen-merge
echo "run.sh: the dataset is in lfgen/ on the claim lfgen-data (copy it out with copy-pod.yaml)"
