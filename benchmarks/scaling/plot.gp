# Plots scaling.csv of scripts/bench-scaling.sh: parallel efficiency and time per step against
# the rank count, one line per mode and scene.
#   gnuplot -e "csv='docs/data/scaling.csv'; png='docs/scaling-2ranks.png'" benchmarks/scaling/plot.gp
if (!exists("csv")) csv = 'scaling.csv'
if (!exists("png")) png = 'scaling.png'
if (!exists("label")) label = ''
set datafile separator ','
set terminal pngcairo size 1100,460 font 'sans,10'
set output png
set multiplot layout 1,2 title 'fdem parallel scaling'.label
set logscale x 2
set xlabel 'MPI ranks'
set grid
set linetype 1 lc rgb '#1f77b4' lw 2
set linetype 2 lc rgb '#d62728' lw 2
set linetype 3 lc rgb '#1f77b4' lw 2
set linetype 4 lc rgb '#d62728' lw 2
set key bottom left
# rows of one mode and scene: column 1 mode, 2 scene, 3 ranks, 8 seconds_per_step, 10 efficiency
sel(m, s, col) = (strcol(1) eq m && strcol(2) eq s) ? column(col) : NaN
set ylabel 'parallel efficiency (strong: T_1/(N T_N), weak: T_1/T_N)'
set yrange [0:1.1]
plot 1 with lines dt 2 lc 'gray' title 'ideal', \
     csv skip 1 using 3:(sel('strong','block',10)) with linespoints lc 1 pt 7 title 'strong, block', \
     csv skip 1 using 3:(sel('strong','wall',10)) with linespoints lc 2 pt 5 title 'strong, wall', \
     csv skip 1 using 3:(sel('weak','block',10)) with linespoints lc 3 pt 6 dt 3 title 'weak, block', \
     csv skip 1 using 3:(sel('weak','wall',10)) with linespoints lc 4 pt 4 dt 3 title 'weak, wall'
set ylabel 'time per step (ms)'
set autoscale y
set yrange [0:*]
set key top left
plot csv skip 1 using 3:(1e3*sel('strong','block',8)) with linespoints lc 1 pt 7 title 'strong, block', \
     csv skip 1 using 3:(1e3*sel('strong','wall',8)) with linespoints lc 2 pt 5 title 'strong, wall', \
     csv skip 1 using 3:(1e3*sel('weak','block',8)) with linespoints lc 3 pt 6 dt 3 title 'weak, block', \
     csv skip 1 using 3:(1e3*sel('weak','wall',8)) with linespoints lc 4 pt 4 dt 3 title 'weak, wall'
unset multiplot
