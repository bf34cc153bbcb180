# The module graph points one way (README's Layout): every #include "module/..." of a file in src/
# names its own module or one below it, no two files include each other, and each external library's
# headers are included by one file.
. "$top_srcdir/tests/lib.sh"
cd "$top_srcdir/src" || exit 1

rank() {
    case $1 in
    base) echo 0 ;; image | geom) echo 1 ;; field) echo 2 ;; fracture | solve) echo 3 ;; model) echo 4 ;;
    render) echo 5 ;; sim) echo 6 ;; io) echo 7 ;; cli) echo 8 ;; *) echo -1 ;;
    esac
}

edges=$(grep -rHo '^#include "[a-z]*/[^"]*"' --include='*.c' --include='*.h' --include='*.cpp' . |
    sed 's|^\./||; s|:#include "| |; s|"$||')
bad=0
printf '%s\n' "$edges" | {
    while read -r file inc; do
        from=${file%%/*} to=${inc%%/*}
        rf=$(rank "$from") rt=$(rank "$to")
        [ "$rt" -lt 0 ] && continue
        if [ "$rt" -gt "$rf" ] || { [ "$rt" -eq "$rf" ] && [ "$from" != "$to" ]; }; then
            echo "    $file includes $inc ($from -> $to)"
            bad=$((bad + 1))
        fi
    done
    [ "$bad" -eq 0 ]
} && ok "no include points up the module graph" || not_ok "includes against the module graph"

mutual=$(printf '%s\n' "$edges" | awk '{ e[$1 " " $2] = 1 } END { for (k in e) { split(k, p, " "); if (e[p[2] " " p[1]]) print "    " p[1] " <-> " p[2] } }')
[ -z "$mutual" ] && ok "no two files include each other" || { not_ok "files that include each other"; echo "$mutual"; }

for lib in 'libqhull_r/' 'cholmod' 'GL/osmesa' 'opencv2/' 'jansson' 'ini\.h'; do
    users=$(grep -rl "^#include <$lib" . | sort)
    n=$(printf '%s' "$users" | grep -c .)
    [ "$n" -le 1 ] && ok "<$lib...> included by at most one file ($users)" ||
        { not_ok "<$lib...> included by $n files"; printf '    %s\n' $users; }
done

# models never include sim, render, io or cli, and kernels never include a model
up=$(grep -rl '^#include "\(sim\|render\|io\|cli\)/' model || true)
[ -z "$up" ] && ok "no model includes sim, render, io or cli" || { not_ok "models include upper layers"; echo "$up"; }
up=$(grep -rl '^#include "model/' fracture geom solve field base || true)
[ -z "$up" ] && ok "no kernel includes a model header" || { not_ok "kernels include model headers"; echo "$up"; }
finish
