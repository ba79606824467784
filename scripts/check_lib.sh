# Shared by the Ant check scripts (source it): each check writes one file, and a rerun skips the checks whose file
# holds something, so files must be written whole: a check killed midway must not leave a file that reads as done.

# write_whole FILE CMD...: CMD's stdout into FILE via FILE.tmp, renamed only if CMD succeeded.
write_whole() {
    local file=$1
    shift
    "$@" > "$file.tmp" || { local rc=$?; rm -f "$file.tmp"; return "$rc"; }
    mv "$file.tmp" "$file"
}

# produce FILE CMD...: write_whole, unless FILE already holds a finished check.
produce() { [ -s "$1" ] || write_whole "$@"; }

# produce_self FILE CMD...: CMD writes FILE whole itself (experiments.failures --out does); skipped like produce.
produce_self() { [ -s "$1" ] || "${@:2}"; }

# leg_kinds_md OUT PY "TAGS" "POINTS": OUT/leg_kinds.md, the lost episodes by kind of leg on the held-out U-chain 2
# paths, per tag (in TAGS' order) and goal-point rule (POINTS: "sampled" and/or "centre", in that order).
leg_kinds_md() { write_whole "$1/leg_kinds.md" leg_kinds_lines "$@"; }

leg_kinds_lines() {
    local out=$1 py=$2 tag points prefix shown
    for tag in $3; do
        for points in $4; do
            prefix=""
            [ "$points" = centre ] && prefix=centre_
            shown="$py -m specrefine.experiments.legs --failures $out/u_chain_2_s[012]_$prefix$tag.json"
            echo "**$tag, held-out U-chain 2 paths, $points goal points** (\`$shown\`)"
            echo
            # errexit does not reach into a command run under ||, so a failure must be passed on by hand
            $py -m specrefine.experiments.legs --failures "$out"/u_chain_2_s[012]_$prefix$tag.json || return
            echo
        done
    done
}
