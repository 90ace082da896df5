#!/usr/bin/env bash
# reports/codes: what real contact codes converge at. Exports each problem, solves it with
# GetFEM 5.4 (both contact bricks) and Kratos 10.4 (mortar ALM), grades every solution beside
# this project's cones, and assembles reports/codes. Not run in CI (the libraries are not
# installed there). Measured on 2 cores on 2026-12-01: exports and outside solves 24.6 min
# (21:52:16-22:16:50), the 27 grades and `codes` 3.8 min.
#
# Install first:
#   apt-get install -y python3-getfem                      # GetFEM 5.4, Debian's python3
#   pip install KratosMultiphysics KratosStructuralMechanicsApplication \
#       KratosContactStructuralMechanicsApplication KratosLinearSolversApplication
#
# Usage: bash examples/codes/run.sh [WORK_DIR]   (default: target/codes)
set -euo pipefail
cd "$(dirname "$0")/../.."
work=${1:-target/codes}
cargo build --release
bin=target/release/contact-rates
export OMP_NUM_THREADS=1
# problem name, study, levels
problems=(
  "rates-exact rates-exact 0-4"
  "crossover crossover 0-6"
  "regularity-0.60 regularity/beta-0.60 0-5"
  "regularity-0.75 regularity/beta-0.75 0-5"
  "regularity-0.90 regularity/beta-0.90 0-5"
  "regularity-1.25 regularity/beta-1.25 0-5"
  "regularity-1.50 regularity/beta-1.50 0-5"
  "regularity-2.00 regularity/beta-2.00 0-5"
  "patch patch 0-3"
)
rm -rf "$work/grades"
for entry in "${problems[@]}"; do
  read -r name study levels <<<"$entry"
  problem="$work/problems/$name"
  [ -d "$problem" ] || $bin export --study "$study" --levels "$levels" --out "$problem"
  for brick in integral nodal; do
    /usr/bin/python3 examples/grade_getfem.py "$problem" "$work/solutions/$name/getfem-$brick" --brick "$brick"
  done
  python3 examples/grade_kratos.py "$problem" "$work/solutions/$name/kratos-alm"
  for code in getfem-integral getfem-nodal kratos-alm; do
    $bin grade --study "$study" --solutions "$work/solutions/$name/$code" --name "$code" \
      --out "$work/grades/$name/$code"
  done
done
$bin codes --grades "$work/grades" --out reports/codes
