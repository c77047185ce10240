# The medians of a side-by-side script's pair lines (side_by_side.sh, jolt_side_by_side.sh):
# each line is `SCENE key=value ...`; prints one line with the median of each field named in
# `fields` (space-separated), labelled by `labels` (comma-separated, same order), ratios
# (a field named ratio) to two decimals and the rest to one.
#
#   grep "^SCENE threads=T " RESULTS | awk -f medians.awk -v name=SCENE -v t=T -v fields="a b ratio" -v labels="A,B,ratio"
function median(a, n,   i, j, x) {
    for (i = 2; i <= n; i++) { x = a[i]; for (j = i - 1; j >= 1 && a[j] > x; j--) a[j + 1] = a[j]; a[j + 1] = x }
    return n % 2 ? a[(n + 1) / 2] : (a[n / 2] + a[n / 2 + 1]) / 2
}
{ for (f = 2; f <= NF; f++) { split($f, kv, "="); v[kv[1], NR] = kv[2] } n = NR }
END {
    k = split(fields, key, " ")
    split(labels, label, ",")
    line = sprintf("  %-14s %d thread(s):", name, t)
    for (f = 1; f <= k; f++) {
        for (i = 1; i <= n; i++) column[i] = v[key[f], i]
        line = line sprintf(key[f] == "ratio" ? "  %s %.2f" : "  %s %.1f", label[f], median(column, n))
    }
    printf "%s  (%d pairs)\n", line, n
}
