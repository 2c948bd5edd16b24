#!/usr/bin/env bash
# The PETSc back end (cargo feature `petsc`): installs PETSc and MPI, runs stamp-petsc's tests
# (distributed solves on 1, 2 and 4 ranks), then every shipped example with `mpirun -n P stamp run`
# on 1, 2 and 4 ranks (the laminate on a coarser mesh; the friction examples too) against the
# default (faer) run: every history.csv column within 1e-8 of its scale (.ci/compare_history.py),
# the Newton iterations within 2 of faer's (the same on every example when measured), with
# friction the numbers of sticking and slipping points of every step faer's; and failing ranks (a rank
# that fails alone, a Newton failure, a bad problem file): every rank ends, one message.
# About 2 minutes on the 2-core machine after the builds (see the timing it prints).
set -euo pipefail
cd "$(dirname "$0")/.."
start=$SECONDS
# OpenBLAS: Debian's PETSc links libblas.so.3, which is the reference BLAS unless an optimised one
# is installed; MUMPS's factorisations are 3 times slower on it (docs/parallel.md)
if ! pkg-config --exists PETSc 2>/dev/null || ! command -v mpirun >/dev/null 2>&1 || ! ls /usr/lib/llvm-*/lib/libclang*.so* >/dev/null 2>&1 || ! ls /usr/lib/x86_64-linux-gnu/openblas-pthread/libblas.so.3 >/dev/null 2>&1; then
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libpetsc-real-dev openmpi-bin libopenmpi-dev libclang-dev pkg-config libopenblas0-pthread >/dev/null
fi
export OMP_NUM_THREADS=1
mpirun=(mpirun --oversubscribe)
[ "$(id -u)" = 0 ] && mpirun+=(--allow-run-as-root)
work=$(mktemp -d)
trap 'rm -rf "$work" meshes/.ci-petsc-*.toml' EXIT
passed=0
failed=0
ok() { passed=$((passed + 1)); }
bad() { echo "FAILED: $*"; failed=$((failed + 1)); }

# the reference: the default build
cargo build --release -p stamp-cli
cp target/release/stamp "$work/stamp-faer"
cargo test --release -p stamp-petsc
cargo build --release -p stamp-cli --features petsc
stamp=target/release/stamp

for f in meshes/*.toml; do
  name=$(basename "$f" .toml)
  # both runs converge Newton to 1e-12 of the force scale (the default 1e-10 left the force of
  # sphere-ss-displacement 1.01e-8 apart on 4 ranks, 3e-9 at 1e-12); the copy stays beside the
  # original, whose relative paths it keeps
  case_file="meshes/.ci-petsc-$name.toml"
  sed 's/^\[solver\]/[solver]\nrel_tol = 1e-12/' "$f" >"$case_file"
  # the laminate (13 surfaces: minutes on PETSc at its 40 x 40) runs on 12 x 12
  [ "$name" = laminate-sphere ] && sed -i 's/n = \[40, 40\]/n = [12, 12]/' "$case_file"
  "$work/stamp-faer" run "$case_file" --out "$work/faer-$name" -q 2>/dev/null || { bad "$name: the faer run failed"; continue; }
  tol=1e-8
  for ranks in 1 2 4; do
    out="$work/p$ranks-$name"
    if ! timeout 300 "${mpirun[@]}" -n "$ranks" "$stamp" run "$case_file" --out "$out" -q 2>"$out.err"; then
      bad "$name on $ranks ranks: $(tail -3 "$out.err")"
      continue
    fi
    if python3 .ci/compare_history.py "$work/faer-$name/history.csv" "$out/history.csv" "$tol" && \
       python3 -c "import json,sys; s=json.load(open('$out/summary.json')); f=json.load(open('$work/faer-$name/summary.json')); stick_slip=lambda r: [(k, p.get('sticking_nodes'), p.get('slipping_nodes')) for x in r['steps'] for k, p in sorted(x['punches'].items())]; sys.exit(0 if s['ranks'] == $ranks and s['linear_solver'].startswith('PETSc') and s['status'] == 'converged' and abs(s['newton_iterations'] - f['newton_iterations']) <= 2 and stick_slip(s) == stick_slip(f) else 1)"; then
      ok
    else
      bad "$name on $ranks ranks differs from the faer run, or its summary.json does not say ranks = $ranks and PETSc, or its Newton iterations are not within 2 of faer's (the re-solve of the linearised contact problem runs on every rank), or its numbers of sticking and slipping points per step are not faer's"
    fi
  done
done

# integrated contact (sphere-ss on 16 x 16 with contact = "integrated"): the pattern grows as
# contact reaches points it did not couple, on some ranks' own patterns only (4 symbolic
# factorisations in this run): every rank builds its matrices anew together
sed -e 's/^\[solver\]/[solver]\nrel_tol = 1e-12/' -e 's/^penetration_tolerance = 1e-6.*/&\ncontact = "integrated"/' -e 's/n = \[10, 10\]/n = [16, 16]/' meshes/sphere-ss.toml >"$work/integrated.toml"
if "$work/stamp-faer" run "$work/integrated.toml" --out "$work/faer-integrated" -q 2>/dev/null; then
  for ranks in 2 4; do
    if timeout 300 "${mpirun[@]}" -n "$ranks" "$stamp" run "$work/integrated.toml" --out "$work/p$ranks-integrated" -q 2>"$work/integrated.err" && \
       python3 .ci/compare_history.py "$work/faer-integrated/history.csv" "$work/p$ranks-integrated/history.csv" 1e-8; then
      ok
    else
      bad "integrated contact on $ranks ranks: $(tail -3 "$work/integrated.err")"
    fi
  done
else
  bad "integrated contact: the faer run failed"
fi

# friction with integrated contact (meshes/sphere-slide-friction.toml with contact = "integrated",
# its penetration_tolerance 1e-5: the friction state at the face's quadrature points, shared by
# the ranks whose points are in their cells). 2 and 4 ranks against 1 rank within 1e-8 (measured
# up to 2.7e-12); 1 rank against the faer run within 1e-7: the two linear solvers' round-off
# grows along this path of 24 steps and 231 cut-back iterations to 2.2e-8 of the peak pressure
# (3e-9 of the displacements), on 1 rank as on 4; the same Newton iterations and stick/slip counts
sed -e 's/^\[solver\]/[solver]\nrel_tol = 1e-12/' -e 's/^friction = 0.2/&\ncontact = "integrated"/' -e 's/^penetration_tolerance = 1e-7/penetration_tolerance = 1e-5/' meshes/sphere-slide-friction.toml >"$work/integrated-friction.toml"
grep -q '^contact = "integrated"' "$work/integrated-friction.toml" || bad "the integrated friction problem was not made"
stick_slip="import json,sys; a,b=(json.load(open(f)) for f in sys.argv[1:3]); c=lambda r: (r['newton_iterations'], [(p.get('sticking_nodes'), p.get('slipping_nodes')) for x in r['steps'] for p in x['punches'].values()]); sys.exit(0 if c(a) == c(b) else 1)"
if "$work/stamp-faer" run "$work/integrated-friction.toml" --out "$work/faer-integrated-friction" -q 2>/dev/null; then
  for ranks in 1 2 4; do
    out="$work/p$ranks-integrated-friction"
    if [ "$ranks" = 1 ]; then ref="$work/faer-integrated-friction"; tol=1e-7; else ref="$work/p1-integrated-friction"; tol=1e-8; fi
    if timeout 300 "${mpirun[@]}" -n "$ranks" "$stamp" run "$work/integrated-friction.toml" --out "$out" -q 2>"$out.err" && \
       python3 .ci/compare_history.py "$ref/history.csv" "$out/history.csv" "$tol" && \
       python3 -c "$stick_slip" "$ref/summary.json" "$out/summary.json"; then
      ok
    else
      bad "friction with integrated contact on $ranks ranks differs from $ref, or its Newton iterations or stick/slip counts do: $(tail -3 "$out.err")"
    fi
  done
else
  bad "friction with integrated contact: the faer run failed"
fi

# rank 0 cannot make its output folder: the failure is agreed at once, one message on every rank
t0=$SECONDS
if timeout 120 "${mpirun[@]}" -n 2 "$stamp" run meshes/sphere-ss.toml --out /proc/stamp-cannot-write -q 2>"$work/folder.err"; then
  bad "an output folder rank 0 cannot make: the job succeeded"
elif [ $? = 124 ]; then
  bad "an output folder rank 0 cannot make: the job hung"
elif [ "$(grep -c '^error: ' "$work/folder.err")" = 1 ] && grep -q "^error: /proc/stamp-cannot-write" "$work/folder.err" && [ $((SECONDS - t0)) -lt 15 ]; then
  ok
else
  bad "an output folder rank 0 cannot make ($((SECONDS - t0)) s): $(cat "$work/folder.err")"
fi
# rank 1 alone fails before the solve (its problem file is missing) while rank 0 waits for it in
# a collective call: rank 1 ends the job with its message (MPI_Abort) after ALONE_AFTER seconds
t0=$SECONDS
if timeout 120 "${mpirun[@]}" -n 1 "$stamp" run meshes/sphere-ss.toml --out "$work/alone" -q : -n 1 "$stamp" run "$work/no-such.toml" -q 2>"$work/alone.err"; then
  bad "a rank that failed alone: the job succeeded"
elif [ $? = 124 ]; then
  bad "a rank that failed alone: the job hung"
elif grep -q "^error: rank 1 of 2: .*no-such.toml" "$work/alone.err"; then
  echo "a rank that failed alone ended the job in $((SECONDS - t0)) s"; ok
else
  bad "a rank that failed alone: $(cat "$work/alone.err")"
fi
# the ranks other than 0 write no file: rank 1, given an output folder of its own, leaves it
# unmade, and nothing in the job's TMPDIR; rank 0's folder is complete
mkdir "$work/tmp"
if timeout 300 "${mpirun[@]}" -x TMPDIR="$work/tmp" -n 1 "$stamp" run meshes/.ci-petsc-sphere-ss.toml --out "$work/writer" -q : -n 1 "$stamp" run meshes/.ci-petsc-sphere-ss.toml --out "$work/not-written" -q 2>"$work/writer.err" && \
   ! [ -e "$work/not-written" ] && [ -z "$(ls -A "$work/tmp")" ] && \
   python3 .ci/compare_history.py "$work/faer-sphere-ss/history.csv" "$work/writer/history.csv" 1e-8 && \
   [ "$(ls -A "$work/writer" | grep -c '\.vtu$')" = 5 ] && [ "$(ls -A "$work/faer-sphere-ss" | grep -c '\.vtu$')" = 5 ]; then
  ok
else
  bad "ranks other than 0 wrote files, or rank 0's outputs are incomplete: $(ls -A "$work/tmp" "$work/not-written" 2>&1 | head -5) $(cat "$work/writer.err")"
fi
# a Newton failure on 2 ranks: one message, summary.json failed
sed -e 's/^\[solver\]/[solver]\nmax_iterations = 2\nmax_cutbacks = 1/' -e "s|file = \"|file = \"$PWD/meshes/|" meshes/sphere-ss.toml >"$work/newton.toml"
if timeout 120 "${mpirun[@]}" -n 2 "$stamp" run "$work/newton.toml" --out "$work/newton" -q 2>"$work/newton.err"; then
  bad "a Newton failure on 2 ranks: the job succeeded"
elif [ "$(grep -c '^error: Newton-Raphson did not converge' "$work/newton.err")" = 1 ] && \
     python3 -c "import json,sys; s=json.load(open('$work/newton/summary.json')); sys.exit(0 if s['status'] == 'failed' and s['ranks'] == 2 else 1)"; then
  ok
else
  bad "a Newton failure on 2 ranks: $(cat "$work/newton.err")"
fi
# a punch whose Psi is not finite at points the plate reaches during the solve (near one corner,
# which one rank's points reach): one message on 4 ranks, the one-process run's, summary.json failed
sed -e 's|- 1"$|- 1 + 0 * sqrt(0.7 - x3 + 0.1 * ((20 - x1) + (20 - x2)))"|' -e "s|file = \"|file = \"$PWD/meshes/|" meshes/ellipsoid-expression.toml >"$work/nan.toml"
grep -q 'sqrt(0.7' "$work/nan.toml" || bad "the Psi-failure problem was not made"
"$stamp" run "$work/nan.toml" --out "$work/nan-1" -q 2>"$work/nan-1.err" && bad "the Psi-failure problem ran to its end on one process"
if timeout 120 "${mpirun[@]}" -n 4 "$stamp" run "$work/nan.toml" --out "$work/nan" -q 2>"$work/nan.err"; then
  bad "a Psi failure on 4 ranks: the job succeeded"
elif [ "$(grep -c '^error: ' "$work/nan.err")" = 1 ] && grep -q "psi is NaN at x = (" "$work/nan.err" && \
     [ "$(grep '^error: ' "$work/nan.err")" = "$(grep '^error: ' "$work/nan-1.err")" ] && \
     python3 -c "import json,sys; s=json.load(open('$work/nan/summary.json')); sys.exit(0 if s['status'] == 'failed' and 'psi is NaN' in s['error'] else 1)"; then
  ok
else
  bad "a Psi failure on 4 ranks: $(cat "$work/nan.err") against one process: $(cat "$work/nan-1.err")"
fi
# ranks whose problem files differ (E on rank 1): refused before the solve, not a deadlock
sed 's/^E = 2.1e5/E = 2.0e5/' meshes/sphere-ss-displacement.toml >"$work/other-e.toml"
if timeout 120 "${mpirun[@]}" -n 1 "$stamp" run meshes/sphere-ss-displacement.toml --out "$work/diff" -q : -n 1 "$stamp" run "$work/other-e.toml" --out "$work/diff" -q 2>"$work/diff.err"; then
  bad "ranks with different problem files: the job succeeded"
elif [ $? = 124 ]; then
  bad "ranks with different problem files: the job hung"
elif grep -q "the ranks read different problems" "$work/diff.err"; then
  ok
else
  bad "ranks with different problem files: $(cat "$work/diff.err")"
fi
# a bad problem file on 4 ranks: one message
printf '[mesh]\nrectangle = [1, 1]\nno_such_key = 3\n' >"$work/bad.toml"
if timeout 120 "${mpirun[@]}" -n 4 "$stamp" run "$work/bad.toml" -q 2>"$work/bad.err"; then
  bad "a bad problem file on 4 ranks: the job succeeded"
elif [ "$(grep -c '^error: ' "$work/bad.err")" = 1 ] && grep -q "no_such_key" "$work/bad.err"; then
  ok
else
  bad "a bad problem file on 4 ranks: $(cat "$work/bad.err")"
fi

# Ctrl-C under mpirun: a longer run (sphere-ss on 80 x 80) on 2 ranks, signalled once its solve is
# under way. (1) SIGINT to mpirun, which sends every rank SIGTERM and SIGKILL a second later: the
# job ends within seconds, summary.json says "interrupted" (written at the signal if the ranks
# are killed before they end the run), no rank is left. (2) SIGINT to rank 1 alone: the ranks
# agree at Newton's next check and end cleanly, one message, exit status 130 (mpirun's too).
sed 's/n = \[10, 10\]/n = [80, 80]/' meshes/sphere-ss.toml >"$work/long.toml"
interrupt_case() { # $1: case name, $2: "mpirun" or "rank1"
  local out="$work/sig-$1" pid child r1="" t0 code
  "${mpirun[@]}" -n 2 "$stamp" run "$work/long.toml" --out "$out" -q 2>"$out.err" &
  pid=$!
  t0=$SECONDS
  until grep -qs '"running"' "$out/summary.json" || [ $((SECONDS - t0)) -gt 120 ]; do sleep 0.2; done
  sleep 2
  if [ "$2" = mpirun ]; then
    kill -INT "$pid"
  else
    for child in $(pgrep -P "$pid"); do
      tr '\0' '\n' <"/proc/$child/environ" 2>/dev/null | grep -qx OMPI_COMM_WORLD_RANK=1 && r1=$child
    done
    [ -n "$r1" ] && kill -INT "$r1"
  fi
  t0=$SECONDS
  while kill -0 "$pid" 2>/dev/null && [ $((SECONDS - t0)) -lt 60 ]; do sleep 0.2; done
  if kill -0 "$pid" 2>/dev/null; then
    kill -KILL "$pid"; bad "Ctrl-C ($1): the job did not end within 60 s"; return
  fi
  wait "$pid" && code=0 || code=$?
  local status
  status=$(python3 -c "import json; s=json.load(open('$out/summary.json')); print(s['status'], s['ranks'])" 2>&1)
  if pgrep -f "$out" >/dev/null; then
    bad "Ctrl-C ($1): a rank is left running"
  elif [ "$status" != "interrupted 2" ]; then
    bad "Ctrl-C ($1): summary.json says $status; $(cat "$out.err")"
  elif [ "$2" = rank1 ] && { [ "$code" != 130 ] || [ "$(grep -c '^error: interrupted' "$out.err")" != 1 ] || ! grep -q 'SIGINT' "$out/summary.json"; }; then
    bad "Ctrl-C ($1): exit status $code; $(cat "$out.err")"
  else
    echo "Ctrl-C ($1): the job ended $((SECONDS - t0)) s after the signal, exit status $code"; ok
  fi
}
interrupt_case mpirun mpirun
interrupt_case rank1 rank1

echo "petsc: $((SECONDS - start)) s"
echo "$passed passed, $failed failed"
[ "$failed" = 0 ]
