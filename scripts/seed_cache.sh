#!/usr/bin/env bash
# Seed each cell's evaluation cache with a copy of another method's cell of the same maze, proposer and seed.
#
#   FROM=ours TO=ours-repair DEST=runs/ant_scaling_centre/repair_geometric_centre/cells \
#       bash scripts/seed_cache.sh runs/ant_centre/cells runs/ant_scaling_centre/ours_centre/cells
#
# MAZES="u_chain_3 u_chain_4" (optional) seeds only those mazes' cells.
#
# Cache entries are content-addressed (the SHA-256 of start distribution, legs, policy fingerprint, n, horizon,
# seed, maze and code version: specrefine/evaluation/cache.py), so an entry found there is the evaluation the
# new cell would have simulated; what the new method asks beyond them is simulated as usual, and the
# measurement and calibration episodes are never cached. Existing entries are kept; each entry is copied to a
# temporary name beside it and renamed, so an interrupted copy leaves no partial entry. The new rows'
# evaluations and cache_hits columns say how much was simulated; their wall times compare with nothing.
set -euo pipefail
: "${FROM:?FROM=method whose caches are copied}" "${TO:?TO=method that receives them}" "${DEST:?DEST=cells folder}"
copied=0
for src_root in "$@"; do
  for src in "$src_root"/*__"$FROM"__*; do
    [ -d "$src/cache" ] || continue
    name=$(basename "$src")
    if [ -n "${MAZES:-}" ] && [[ " $MAZES " != *" ${name%%__*} "* ]]; then continue; fi
    dest="$DEST/${name/__${FROM}__/__${TO}__}"
    while IFS= read -r -d '' entry; do
      target="$dest/cache/${entry#"$src/cache/"}"
      [ -e "$target" ] && continue
      mkdir -p "$(dirname "$target")"
      cp "$entry" "$target.part$$" && mv "$target.part$$" "$target"
    done < <(find "$src/cache" -type f -name '*.npz' -print0)
    copied=$((copied + 1))
  done
done
echo "seeded $copied cell caches of $TO from $FROM into $DEST"
