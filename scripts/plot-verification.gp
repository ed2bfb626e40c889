# Error against wall time for one problem of the verification suite (log-log).
# Called by scripts/verify.sh, which writes one file per series into `dir`:
#   <dir>/<quantity>.<sweep>.series   rows "wall_seconds error tolerance", sorted by wall time
# (a series: one quantity, one swept parameter, plus the problem's base run), as
#   gnuplot -e "dir='/tmp/x'; problem='two_bar_impact'; quantities='contact_time interface_stress'; \
#               sweeps='h penalty_ratio'; png='docs/verification/two_bar_impact.png'" \
#           scripts/plot-verification.gp
# Colour: the quantity; point type: the swept parameter; dashed line: the quantity's tolerance.
# Errors below 1e-16 are drawn at 1e-16.
set terminal pngcairo size 1100,650 font ',10'
set output png
set logscale xy
set format y '10^{%L}'
set xlabel 'wall time per run (s)'
set ylabel 'error (relative; absolute for drifts and balances)'
set title sprintf('%s: error against run time', problem) noenhanced
set key outside right top noenhanced
set grid
clamp_error(e) = e < 1e-16 ? 1e-16 : e
nq = words(quantities)
ns = words(sweeps)
file(i) = sprintf('%s/%s.%s.series', dir, word(quantities, (i-1)/ns+1), word(sweeps, (i-1)%ns+1))
tolerance_file(j) = sprintf('%s/%s.%s.series', dir, word(quantities, j), word(sweeps, 1))
plot for [i=1:nq*ns] file(i) using 1:(clamp_error($2)) \
       with linespoints lc (i-1)/ns+1 dt 1 pt 2*((i-1)%ns)+5 ps 1.3 \
       title sprintf('%s vs %s', word(quantities, (i-1)/ns+1), word(sweeps, (i-1)%ns+1)), \
     for [j=1:nq] tolerance_file(j) using 1:($3 > 0 ? $3 : NaN) \
       with lines lc j dt 2 lw 1.5 title sprintf('tolerance: %s', word(quantities, j))
