#!/usr/bin/env bash
# reports/codes is made by the Snakemake workflow in workflow/Snakefile (docs/verify-your-code.md#the-workflow): this runs it here on the machine's cores.
set -euo pipefail; cd "$(dirname "$0")/../.." && cargo build --release && exec "${SNAKEMAKE:-snakemake}" --cores "${CORES:-2}" "$@"
