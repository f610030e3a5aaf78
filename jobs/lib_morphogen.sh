# shellcheck shell=bash
# Shared logic of the morphogen job scripts (run.sbatch, array.sbatch, sweep_array.sbatch and
# their .pbs twins): configuration from the environment, the time left in the job
# (-> -max_walltime), launching the run in the background with SIGUSR1/SIGTERM forwarded to it,
# and what to do with its exit code (resubmit on 3, with a cap and a progress check). Sourced,
# never run; see jobs/README.md.
#
# A job script does:
#   mg_init slurm|pbs SCRIPT_NAME "$@"   # read the configuration (exits 1 on a bad one)
#   mg_member | mg_sweep_member           # arrays only: pick this task's member / sweep chunk
#   mg_run                                # run morphogen, sets MG_RC
#   mg_finish                             # exit code handling, resubmission; exits
#
# Exit codes of morphogen (runs and sweeps): 0 done, 1 bad input or diverged, 2 internal error,
# 3 stopped on a signal or on -max_walltime, resumable (resubmit), 4 output write failed.

MG_EXIT_DONE=0
MG_EXIT_INPUT=1
MG_EXIT_INTERNAL=2
MG_EXIT_RESUBMIT=3
MG_EXIT_WRITE=4

# Log to standard error (the job's log file).
mg_log() {
  printf '%s morphogen-job: %s\n' "$(date '+%Y-%m-%d %H:%M:%S')" "$*" >&2
}

# Log, and append the line to the run's history file in the output directory.
mg_note() {
  mg_log "$@"
  if [[ -n ${MG_OUT:-} && -d $MG_OUT ]]; then
    printf '%s job %s: %s\n' "$(date '+%Y-%m-%d %H:%M:%S')" "$(mg_job_id)" "$*" \
      >>"$MG_OUT/morphogen_jobs.log" 2>/dev/null || true
  fi
}

mg_die() { # CODE MESSAGE...
  local code=$1
  shift
  mg_log "error: $*"
  exit "$code"
}

mg_job_id() {
  printf '%s' "${SLURM_JOB_ID:-${PBS_JOBID:-local}}"
}

mg_is_uint() {
  [[ $1 =~ ^[0-9]+$ ]]
}

# Split STRING into words like a shell does (single and double quotes, backslashes; no
# expansion of variables or globs) into the array named NAME. Fails on unbalanced quotes.
mg_split_words() { # NAME STRING
  local out=""
  if [[ $2 =~ [^[:space:]] ]]; then
    out=$(printf '%s\n' "$2" | xargs -r printf '%s\n' 2>/dev/null) || return 1
  fi
  if [[ -n $out ]]; then
    mapfile -t "$1" <<<"$out"
  else
    mapfile -t "$1" </dev/null
  fi
}

# The words as one line that a shell would split back into them (for the log).
mg_quote() { # WORDS...
  local w q="'\\''" line=""
  for w in "$@"; do
    if [[ ! $w =~ ^[A-Za-z0-9_./,:=+%@-]+$ ]]; then
      w="'${w//\'/$q}'"
    fi
    line+="${line:+ }$w"
  done
  printf '%s' "$line"
}

# Duration in seconds of a scheduler time string. SLURM (--time, squeue %L, scontrol):
# [D-]H:M:S, M:S, D-H, D-H:M, or a lone number of minutes; PBS (walltime): H:M:S, M:S or a lone
# number of seconds. LONE_UNIT is the lone number's unit in seconds (60 for SLURM, 1 for PBS).
# Prints the seconds; fails (status 1) on anything else (UNLIMITED, NOT_SET, INVALID, junk).
mg_duration_seconds() { # STRING LONE_UNIT
  local s=$1 unit=$2 days=0 parts
  s=${s//[[:space:]]/}
  s=${s%%.*} # PBS may append fractions of a second
  if [[ $s =~ ^([0-9]+)-(.+)$ ]]; then
    days=${BASH_REMATCH[1]}
    s=${BASH_REMATCH[2]}
    [[ $s =~ ^[0-9]+(:[0-9]+){0,2}$ ]] || return 1
    IFS=: read -r -a parts <<<"$s"
    # after "D-" the fields are H, H:M or H:M:S
    printf '%d\n' $((10#$days * 86400 + 10#${parts[0]} * 3600 + 10#${parts[1]:-0} * 60 + 10#${parts[2]:-0}))
    return 0
  fi
  [[ $s =~ ^[0-9]+(:[0-9]+){0,2}$ ]] || return 1
  IFS=: read -r -a parts <<<"$s"
  case ${#parts[@]} in
    1) printf '%d\n' $((10#${parts[0]} * unit)) ;;
    2) printf '%d\n' $((10#${parts[0]} * 60 + 10#${parts[1]})) ;;
    3) printf '%d\n' $((10#${parts[0]} * 3600 + 10#${parts[1]} * 60 + 10#${parts[2]})) ;;
  esac
}

# Seconds left in this job, from the batch system; fails when not known (not in a job, the
# query commands missing or failing, no limit).
mg_time_left_seconds() {
  local out limit used
  case $MG_SCHED in
    slurm)
      [[ -n ${SLURM_JOB_ID:-} ]] || return 1
      if out=$(squeue -h -j "$SLURM_JOB_ID" -o %L 2>/dev/null) &&
        mg_duration_seconds "$out" 60; then
        return 0
      fi
      out=$(scontrol show job "$SLURM_JOB_ID" 2>/dev/null) || return 1
      [[ $out =~ TimeLimit=([^[:space:]]+) ]] || return 1
      limit=$(mg_duration_seconds "${BASH_REMATCH[1]}" 60) || return 1
      used=0
      if [[ $out =~ RunTime=([^[:space:]]+) ]]; then
        used=$(mg_duration_seconds "${BASH_REMATCH[1]}" 60) || used=0
      fi
      printf '%d\n' $((limit - used))
      ;;
    pbs)
      if [[ -n ${PBS_JOBID:-} ]] && out=$(qstat -f "$PBS_JOBID" 2>/dev/null) &&
        [[ $out =~ Resource_List\.walltime[[:space:]]*=[[:space:]]*([^[:space:]]+) ]] &&
        limit=$(mg_duration_seconds "${BASH_REMATCH[1]}" 1); then
        used=0
        if [[ $out =~ resources_used\.walltime[[:space:]]*=[[:space:]]*([^[:space:]]+) ]]; then
          used=$(mg_duration_seconds "${BASH_REMATCH[1]}" 1) || used=0
        fi
        printf '%d\n' $((limit - used))
        return 0
      fi
      # Torque sets the requested walltime in seconds
      mg_is_uint "${PBS_WALLTIME:-}" || return 1
      printf '%d\n' "$PBS_WALLTIME"
      ;;
    *) return 1 ;;
  esac
}

# The -max_walltime value in whole minutes: MORPHOGEN_MAX_WALLTIME if it is a number, nothing
# if it is "off" (or the time left is unknown or too short), else the time left in the job
# minus MORPHOGEN_WALLTIME_MARGIN seconds.
mg_max_walltime_minutes() {
  local mode=${MORPHOGEN_MAX_WALLTIME:-auto} left margin=${MORPHOGEN_WALLTIME_MARGIN:-240}
  case $mode in
    off | none | 0) return 1 ;;
    auto) ;;
    *)
      printf '%s\n' "$mode"
      return 0
      ;;
  esac
  if ! left=$(mg_time_left_seconds); then
    mg_log "time left in the job unknown: no -max_walltime (the signal is the only warning)"
    return 1
  fi
  if ((left - margin < 60)); then
    mg_log "only ${left} s left in the job, margin ${margin} s: no -max_walltime"
    return 1
  fi
  printf '%d\n' $(((left - margin) / 60))
}

# Newest checkpoint file name in DIR (highest step), empty when there is none.
mg_latest_checkpoint() { # DIR
  local f best="" best_step=-1 step
  for f in "$1"/checkpoint_*.vtkhdf; do
    [[ -e $f ]] || continue
    step=${f##*/checkpoint_}
    step=${step%.vtkhdf}
    mg_is_uint "$step" || continue
    if ((10#$step > best_step)); then
      best_step=$((10#$step))
      best=${f##*/}
    fi
  done
  printf '%s' "$best"
}

# Read the configuration. SCHED: slurm or pbs; SCRIPT_NAME: the job script's file name in
# jobs/ (what a resubmission submits unless MORPHOGEN_JOB_SCRIPT says otherwise); then the
# script's own arguments (SLURM only: a deck and/or morphogen options).
mg_init() { # SCHED SCRIPT_NAME ARGS...
  MG_SCHED=$1
  MG_SCRIPT_NAME=$2
  shift 2
  MG_SCRIPT_ARGS=("$@")
  MORPHOGEN_JOBS_DIR=$(cd "${MORPHOGEN_JOBS_DIR:-.}" && pwd) || mg_die 2 "MORPHOGEN_JOBS_DIR not found"
  export MORPHOGEN_JOBS_DIR
  case $MG_SCHED in
    slurm) ;;
    pbs)
      ((${#MG_SCRIPT_ARGS[@]} == 0)) ||
        mg_die 1 "PBS passes no arguments to a job script; use DECK, OUT and EXTRA_ARGS"
      cd "${PBS_O_WORKDIR:-.}" || mg_die 1 "cannot enter PBS_O_WORKDIR=$PBS_O_WORKDIR"
      ;;
    *) mg_die 2 "mg_init: unknown scheduler $MG_SCHED" ;;
  esac

  local count=${MORPHOGEN_RESUBMIT_COUNT:-0} max=${MORPHOGEN_MAX_RESUBMIT:-10}
  mg_is_uint "$count" || mg_die 1 "MORPHOGEN_RESUBMIT_COUNT=$count: not a count"
  mg_is_uint "$max" || mg_die 1 "MORPHOGEN_MAX_RESUBMIT=$max: not a count"
  MG_COUNT=$((10#$count))
  MG_MAX=$((10#$max))
  [[ ${MORPHOGEN_MAX_WALLTIME:-auto} =~ ^(auto|off|none|[0-9]+)$ ]] ||
    mg_die 1 "MORPHOGEN_MAX_WALLTIME=$MORPHOGEN_MAX_WALLTIME: a number of minutes, auto or off"
  mg_is_uint "${MORPHOGEN_WALLTIME_MARGIN:-240}" ||
    mg_die 1 "MORPHOGEN_WALLTIME_MARGIN=$MORPHOGEN_WALLTIME_MARGIN: a number of seconds"

  MG_EXE=${MORPHOGEN:-${MORPHOGEN_EXE:-build/morphogen}}
  command -v -- "$MG_EXE" >/dev/null || mg_die 1 "MORPHOGEN=$MG_EXE: no such executable"

  if [[ -n ${MORPHOGEN_LAUNCHER:-} ]]; then
    mg_split_words MG_LAUNCHER "$MORPHOGEN_LAUNCHER" || mg_die 1 "MORPHOGEN_LAUNCHER: unbalanced quotes"
  elif [[ $MG_SCHED == slurm ]]; then
    MG_LAUNCHER=(srun)
  else
    MG_LAUNCHER=(mpiexec)
  fi
  mg_split_words MG_EXTRA "${EXTRA_ARGS:-}" || mg_die 1 "EXTRA_ARGS: unbalanced quotes"

  # The deck: DECK, else a first script argument that is not an option.
  MG_ARGS=("${MG_SCRIPT_ARGS[@]}")
  MG_DECK=${DECK:-}
  if [[ -z $MG_DECK && ${#MG_ARGS[@]} -gt 0 && ${MG_ARGS[0]} != -* ]]; then
    MG_DECK=${MG_ARGS[0]}
    MG_ARGS=("${MG_ARGS[@]:1}")
  fi
  [[ -z $MG_DECK || -r $MG_DECK ]] || mg_die 1 "DECK=$MG_DECK: not a readable file"

  # The output directory: OUT, else the last -output_dir of the options, else morphogen's default.
  MG_OUT=${OUT:-}
  if [[ -z $MG_OUT ]]; then
    local i all=("${MG_EXTRA[@]}" "${MG_ARGS[@]}")
    for ((i = 0; i + 1 < ${#all[@]}; i++)); do
      [[ ${all[i]} == -output_dir ]] && MG_OUT=${all[i + 1]}
    done
  fi
  MG_OUT=${MG_OUT:-morphogen_out}
  MG_MEMBER_ARGS=()
  MG_ARRAY_INDEX=""
  # What mg_run launches: $MG_EXE MG_SUBCOMMAND [DECK] -output_dir OUT MG_CHUNK_ARGS ... (the
  # two are set by mg_sweep_member), and how it measures progress (see mg__resubmit_refusal).
  MG_SUBCOMMAND=()
  MG_CHUNK_ARGS=()
  MG_PROGRESS=mg_latest_checkpoint
  MG_PROGRESS_UNIT=checkpoint
}

# This array task's index into MG_ARRAY_INDEX: MORPHOGEN_ARRAY_INDEX (set on a resubmitted
# task), else the batch system's (SLURM_ARRAY_TASK_ID, PBS Pro PBS_ARRAY_INDEX, Torque
# PBS_ARRAYID).
mg__array_index() {
  local idx=${MORPHOGEN_ARRAY_INDEX:-${SLURM_ARRAY_TASK_ID:-${PBS_ARRAY_INDEX:-${PBS_ARRAYID:-}}}}
  mg_is_uint "$idx" ||
    mg_die 1 "not an array task (no SLURM_ARRAY_TASK_ID, PBS_ARRAY_INDEX, PBS_ARRAYID or MORPHOGEN_ARRAY_INDEX)"
  MG_ARRAY_INDEX=$((10#$idx))
}

# Select this array task's ensemble member. Its index: see mg__array_index. With
# ENSEMBLE_FILE, the member's extra options are its INDEX-th member line (numbered from 1; blank
# lines and lines starting with # do not count); without, the member is -seed INDEX. Its output
# goes to OUT/member_NNNN.
mg_member() {
  local idx line n=0 found=""
  mg__array_index
  idx=$MG_ARRAY_INDEX
  if [[ -n ${ENSEMBLE_FILE:-} ]]; then
    [[ -r $ENSEMBLE_FILE ]] || mg_die 1 "ENSEMBLE_FILE=$ENSEMBLE_FILE: not a readable file"
    while IFS= read -r line || [[ -n $line ]]; do
      [[ $line =~ ^[[:space:]]*(#|$) ]] && continue
      n=$((n + 1))
      if ((n == idx)); then
        found=1
        break
      fi
    done <"$ENSEMBLE_FILE"
    [[ -n $found ]] ||
      mg_die 1 "array index $idx: ENSEMBLE_FILE=$ENSEMBLE_FILE has $n member lines (numbered from 1)"
    mg_split_words MG_MEMBER_ARGS "$line" || mg_die 1 "$ENSEMBLE_FILE member $idx: unbalanced quotes"
  else
    MG_MEMBER_ARGS=(-seed "$idx")
  fi
  MG_OUT=$(printf '%s/member_%04d' "$MG_OUT" "$idx")
}

# The progress measure of a sweep chunk (MG_PROGRESS): how many of the chunk's points are
# finished in DIR (DIR/points/point_<p>.json with p mod MG_SWEEP_CHUNKS == MG_SWEEP_CHUNK, so
# that concurrent chunks do not count), as "N finished points"; empty when none.
mg_sweep_points_done() { # DIR
  local f p n=0
  for f in "$1"/points/point_*.json; do
    [[ -e $f ]] || continue
    p=${f##*/point_}
    p=${p%.json}
    mg_is_uint "$p" || continue
    ((10#$p % MG_SWEEP_CHUNKS == MG_SWEEP_CHUNK)) && n=$((n + 1))
  done
  ((n == 0)) || printf '%d finished points' "$n"
}

# Make this array task run one chunk of a sweep: `$MORPHOGEN sweep DECK -output_dir OUT
# -sweep_chunk c -sweep_chunks C ...` with c = INDEX - SWEEP_FIRST_INDEX (INDEX: see
# mg__array_index) and C = SWEEP_CHUNKS. Without SWEEP_CHUNKS, the job array is the sweep: C is
# its size and SWEEP_FIRST_INDEX defaults to its first index; the array must then be contiguous
# (FIRST-LAST, step 1), read from SLURM_ARRAY_TASK_MIN/MAX (and _COUNT, _STEP) or from PBS Pro's
# `qstat -f $PBS_ARRAY_ID` (array_indices_submitted). With SWEEP_CHUNKS, SWEEP_FIRST_INDEX
# defaults to 0 (index i runs chunk i). Both are exported, so that a resubmitted task (a
# one-index array, or a plain PBS job) keeps them. Progress for the resubmission check: more
# finished points of this chunk.
mg_sweep_member() {
  local a first=${SWEEP_FIRST_INDEX:-} chunks=${SWEEP_CHUNKS:-} min="" max="" step="" count="" out
  [[ -n $MG_DECK ]] || mg_die 1 "a sweep needs a deck (DECK, or the first script argument)"
  for a in "${MG_EXTRA[@]}" "${MG_ARGS[@]}"; do
    [[ $a == -sweep_chunk || $a == -sweep_chunks ]] &&
      mg_die 1 "$a: the chunks are the array tasks (set by the script; see SWEEP_CHUNKS)"
  done
  mg__array_index
  case $MG_SCHED in
    slurm)
      min=${SLURM_ARRAY_TASK_MIN:-} max=${SLURM_ARRAY_TASK_MAX:-}
      step=${SLURM_ARRAY_TASK_STEP:-} count=${SLURM_ARRAY_TASK_COUNT:-}
      ;;
    pbs)
      if [[ -z $first || -z $chunks ]] && [[ -n ${PBS_ARRAY_ID:-} ]] &&
        out=$(qstat -f "$PBS_ARRAY_ID" 2>/dev/null) &&
        [[ $out =~ array_indices_submitted[[:space:]]*=[[:space:]]*([0-9]+)-([0-9]+)(:([0-9]+))? ]]; then
        min=${BASH_REMATCH[1]} max=${BASH_REMATCH[2]} step=${BASH_REMATCH[4]:-1}
      fi
      ;;
  esac
  if [[ -z $chunks ]]; then # the array is the sweep: chunk 0 is its first index
    { mg_is_uint "$min" && mg_is_uint "$max"; } ||
      mg_die 1 "the job array's index range is unknown: set SWEEP_CHUNKS (and SWEEP_FIRST_INDEX, default 0)"
    chunks=$((10#$max - 10#$min + 1))
    # contiguous: as many tasks as indices from min to max (else, without a count: step 1)
    if mg_is_uint "$count" && ((10#$count != chunks)) ||
      { ! mg_is_uint "$count" && mg_is_uint "$step" && ((10#$step != 1)); }; then
      mg_die 1 "the job array ($min-$max, ${count:-?} tasks, step ${step:-?}) is not contiguous: use FIRST-LAST (e.g. 0-$((chunks - 1))), or set SWEEP_CHUNKS and SWEEP_FIRST_INDEX"
    fi
    first=${first:-$min}
  fi
  first=${first:-0} # SWEEP_CHUNKS given: index i is chunk i unless SWEEP_FIRST_INDEX says otherwise
  { mg_is_uint "$chunks" && ((10#$chunks >= 1)); } || mg_die 1 "SWEEP_CHUNKS=$chunks: not a positive count"
  mg_is_uint "$first" || mg_die 1 "SWEEP_FIRST_INDEX=$first: not an index"
  export SWEEP_CHUNKS=$((10#$chunks)) SWEEP_FIRST_INDEX=$((10#$first))
  MG_SWEEP_CHUNKS=$SWEEP_CHUNKS
  MG_SWEEP_CHUNK=$((MG_ARRAY_INDEX - SWEEP_FIRST_INDEX))
  ((MG_SWEEP_CHUNK >= 0 && MG_SWEEP_CHUNK < MG_SWEEP_CHUNKS)) ||
    mg_die 1 "array index $MG_ARRAY_INDEX: chunk $MG_SWEEP_CHUNK is not in 0..$((MG_SWEEP_CHUNKS - 1)) (SWEEP_FIRST_INDEX=$SWEEP_FIRST_INDEX, SWEEP_CHUNKS=$SWEEP_CHUNKS)"
  MG_SUBCOMMAND=(sweep)
  MG_CHUNK_ARGS=(-sweep_chunk "$MG_SWEEP_CHUNK" -sweep_chunks "$MG_SWEEP_CHUNKS")
  MG_PROGRESS=mg_sweep_points_done
  MG_PROGRESS_UNIT="finished point of chunk $MG_SWEEP_CHUNK/$MG_SWEEP_CHUNKS"
}

# Forward a checkpoint request to the run. Always SIGUSR1, whatever arrived: morphogen treats
# USR1 and TERM alike, but srun answers SIGTERM by killing the step (SIGKILL) and OpenMPI's
# mpiexec by terminating the job, while both pass SIGUSR1 on to the ranks.
mg__on_signal() { # SIGNAME
  MG_TRAPPED=1
  [[ $1 == TERM ]] && MG_GOT_TERM=1
  if [[ -n ${MG_CHILD:-} ]]; then
    mg_log "received SIG$1: forwarding SIGUSR1 to the run (pid $MG_CHILD) to checkpoint and stop"
    kill -USR1 "$MG_CHILD" 2>/dev/null || true
  else
    mg_log "received SIG$1 before the run started"
    MG_PENDING=1
  fi
}

# Run morphogen (in the background, so that the traps run at once) and wait for it; sets MG_RC.
mg_run() {
  local minutes prev rc
  mkdir -p -- "$MG_OUT" || mg_die "$MG_EXIT_WRITE" "cannot create the output directory $MG_OUT"
  MG_CMD=("$MG_EXE" "${MG_SUBCOMMAND[@]}")
  [[ -n $MG_DECK ]] && MG_CMD+=("$MG_DECK")
  MG_CMD+=(-output_dir "$MG_OUT" "${MG_CHUNK_ARGS[@]}" -restart latest)
  local a user_walltime=""
  for a in "${MG_EXTRA[@]}" "${MG_ARGS[@]}" "${MG_MEMBER_ARGS[@]}"; do
    [[ $a == -max_walltime ]] && user_walltime=1
  done
  if [[ -z $user_walltime ]] && minutes=$(mg_max_walltime_minutes); then
    MG_CMD+=(-max_walltime "$minutes")
  fi
  MG_CMD+=("${MG_EXTRA[@]}" "${MG_ARGS[@]}" "${MG_MEMBER_ARGS[@]}")

  MG_PROGRESS_BEFORE=$("$MG_PROGRESS" "$MG_OUT")
  mg_note "segment $((MG_COUNT + 1)) of at most $((MG_MAX + 1)) starts${MG_PROGRESS_BEFORE:+ from $MG_PROGRESS_BEFORE}: $(mg_quote "${MG_LAUNCHER[@]}" "${MG_CMD[@]}")"

  # The ranks' own exit code: rank 0 writes it to MORPHOGEN_EXIT_FILE on the way out, because
  # the launcher's may differ (Open MPI's mpiexec returns 1 when SIGTERM reached it, although
  # the ranks checkpointed and exited 3).
  MG_EXIT_FILE=$MG_OUT/.morphogen_exit_code
  rm -f -- "$MG_EXIT_FILE"
  # hwloc's OpenCL and GL plugins (an OpenCL ICD such as PoCL loads LLVM, whose SIGUSR1 handler
  # replaces mpiexec's forwarding) would keep the forwarded SIGUSR1 from reaching the ranks.
  export HWLOC_COMPONENTS=${HWLOC_COMPONENTS--opencl,-gl}
  # When the batch system's SIGTERM reaches Open MPI's mpiexec itself, it kills the ranks 1 s
  # later (odls_base_sigkill_timeout), mid-checkpoint: give them time to finish it.
  export OMPI_MCA_odls_base_sigkill_timeout=${OMPI_MCA_odls_base_sigkill_timeout-30}

  MG_TRAPPED=0 MG_GOT_TERM=0 MG_PENDING=0 MG_CHILD=""
  trap 'mg__on_signal USR1' USR1
  trap 'mg__on_signal TERM' TERM
  MORPHOGEN_EXIT_FILE=$MG_EXIT_FILE "${MG_LAUNCHER[@]}" "${MG_CMD[@]}" &
  MG_CHILD=$!
  if ((MG_PENDING)); then
    kill -USR1 "$MG_CHILD" 2>/dev/null || true
  fi
  # A trapped signal interrupts `wait` (status > 128) while the run goes on: wait again.
  prev=""
  while :; do
    MG_TRAPPED=0
    rc=0
    wait "$MG_CHILD" || rc=$?
    if ((rc == 127)) && [[ -n $prev ]]; then # already reaped: its status was the last one
      rc=$prev
      break
    fi
    if ((rc > 128 && MG_TRAPPED)); then
      prev=$rc
      continue
    fi
    break
  done
  # From here on a signal is only noted: the bookkeeping below must not be cut short.
  trap 'mg_log "received SIGUSR1 after the run ended"' USR1
  trap 'mg_log "received SIGTERM after the run ended"; MG_GOT_TERM=1' TERM
  MG_RC=$rc
  mg__ranks_exit_code
}

# If the ranks wrote their exit code (MG_EXIT_FILE) and it differs from the launcher's, use
# theirs: a checkpoint-and-exit-3 must resubmit whatever the launcher made of it.
mg__ranks_exit_code() {
  local code=""
  [[ -r $MG_EXIT_FILE ]] && read -r code <"$MG_EXIT_FILE"
  rm -f -- "$MG_EXIT_FILE"
  mg_is_uint "$code" || return 0
  if ((10#$code != MG_RC)); then
    mg_log "the launcher returned $MG_RC, the ranks exited with $((10#$code)): using $((10#$code))"
    MG_RC=$((10#$code))
  fi
}

# Whether a run that stopped with exit code 3 may be resubmitted; prints the reason if not. A
# run made progress when the measure $MG_PROGRESS prints for MG_OUT (the newest checkpoint's
# name; for sweeps the chunk's number of finished points) is not empty afterwards and differs
# from the one before.
mg__resubmit_refusal() {
  local after
  if ((MG_COUNT >= MG_MAX)); then
    printf 'resubmission cap reached (%d of MORPHOGEN_MAX_RESUBMIT=%d)' "$MG_COUNT" "$MG_MAX"
    return 0
  fi
  if ((MG_GOT_TERM)) && [[ ${MORPHOGEN_RESUBMIT_ON_TERM:-0} != 1 ]]; then
    printf 'the job got SIGTERM (scancel/qdel, or the time limit): not resubmitting unless MORPHOGEN_RESUBMIT_ON_TERM=1'
    return 0
  fi
  if [[ ${MORPHOGEN_REQUIRE_PROGRESS:-1} == 1 ]]; then
    after=$("$MG_PROGRESS" "$MG_OUT")
    if [[ -z $after || $after == "$MG_PROGRESS_BEFORE" ]]; then
      printf 'no new %s in %s (before: %s, now: %s): the run made no progress' \
        "$MG_PROGRESS_UNIT" "$MG_OUT" "${MG_PROGRESS_BEFORE:-none}" "${after:-none}"
      return 0
    fi
  fi
  return 1
}

# Submit this job again, with the same script arguments and environment, one more in the count.
mg_resubmit() {
  local script=${MORPHOGEN_JOB_SCRIPT:-$MORPHOGEN_JOBS_DIR/$MG_SCRIPT_NAME} out rc=0 name
  local -a opts extra
  [[ -r $script ]] || {
    mg_log "job script $script not found (set MORPHOGEN_JOB_SCRIPT)"
    return 1
  }
  script=$(cd "$(dirname -- "$script")" && pwd)/$(basename -- "$script")
  out=$(
    export MORPHOGEN_RESUBMIT_COUNT=$((MG_COUNT + 1)) MORPHOGEN_JOB_SCRIPT=$script
    case $MG_SCHED in
      slurm)
        # The new job inherits this environment (--export=ALL), but not this job's SLURM_*
        # variables: srun would take stale ones (memory, task layout) as its input.
        opts=(--export=ALL)
        [[ -n ${SLURM_JOB_NAME:-} ]] && opts+=("--job-name=$SLURM_JOB_NAME")
        [[ -n $MG_ARRAY_INDEX ]] && opts+=("--array=$MG_ARRAY_INDEX")
        mg_split_words extra "${MORPHOGEN_SBATCH_ARGS:-}" || exit 1
        cd "${SLURM_SUBMIT_DIR:-.}" || exit 1
        for name in "${!SLURM_@}"; do
          [[ $name == SLURM_CONF ]] || unset "$name"
        done
        sbatch "${opts[@]}" "${extra[@]}" "$script" "${MG_SCRIPT_ARGS[@]}"
        ;;
      pbs)
        # -V: the new job gets this environment, less this job's own PBS_* variables. A
        # member of an array comes back as a plain job that knows its index.
        opts=(-V)
        [[ -n ${PBS_JOBNAME:-} ]] && opts+=(-N "$PBS_JOBNAME")
        [[ -n $MG_ARRAY_INDEX ]] && export MORPHOGEN_ARRAY_INDEX=$MG_ARRAY_INDEX
        mg_split_words extra "${MORPHOGEN_QSUB_ARGS:-}" || exit 1
        for name in "${!PBS_@}"; do
          case $name in PBS_DEFAULT | PBS_SERVER | PBS_CONF_FILE | PBS_EXEC | PBS_HOME) ;; *) unset "$name" ;; esac
        done
        qsub "${opts[@]}" "${extra[@]}" "$script"
        ;;
    esac
  ) || rc=$?
  if ((rc != 0)); then
    mg_log "resubmission failed (status $rc): $out"
    return 1
  fi
  mg_note "resubmitted ($((MG_COUNT + 1)) of at most $MG_MAX): ${out//$'\n'/ }"
  return 0
}

# Act on the run's exit code and exit: 0 when done or handed over to a resubmitted job, 3 when
# it stopped early (exit 3) and was not resubmitted, otherwise morphogen's code.
mg_finish() {
  local why
  case $MG_RC in
    "$MG_EXIT_DONE")
      mg_note "run finished (exit 0)"
      exit 0
      ;;
    "$MG_EXIT_RESUBMIT")
      if why=$(mg__resubmit_refusal); then
        mg_note "run stopped early (exit 3, resumable), not resubmitted: $why; submit again to continue"
        exit "$MG_EXIT_RESUBMIT"
      fi
      if mg_resubmit; then
        exit 0
      fi
      mg_note "run stopped early (exit 3, resumable), resubmission failed; submit again to continue"
      exit "$MG_EXIT_RESUBMIT"
      ;;
    "$MG_EXIT_INPUT") why="bad input or diverged run" ;;
    "$MG_EXIT_INTERNAL") why="internal error" ;;
    "$MG_EXIT_WRITE") why="writing output failed" ;;
    *)
      if ((MG_RC > 128)); then
        why="killed by signal $((MG_RC - 128))"
      else
        why="launcher or run failed"
      fi
      ;;
  esac
  mg_note "run failed (exit $MG_RC: $why), not resubmitted"
  exit "$MG_RC"
}
