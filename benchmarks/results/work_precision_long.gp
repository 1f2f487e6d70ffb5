set terminal pngcairo size 1400,1000 font ',10'
set output '/work/main/benchmarks/results/work_precision_long.png'
set logscale xy
set format x '10^{%L}'
set format y '10^{%L}'
set grid
set key top left
set multiplot layout 2,2 title "long: U branch from BP1 to |q| = 1.5 (AUTO A-U, restarted)\nbuckle vs AUTO-07p vs naive load grid; buckle-P2: second-order predictor (lines: lower envelopes; errors of 0 at 1e-17)"
set xlabel 'special-point error |dFx|'
set ylabel 'wall time per run [ms]'
plot '/work/main/benchmarks/results/work_precision_long.dat' index 0 using 5:3 with points pt 7 ps 0.8 lc rgb '#1f77b4' title 'buckle', \
     '' index 1 using 5:3 with lines lw 2 lc rgb '#1f77b4' notitle, \
     '/work/main/benchmarks/results/work_precision_long.dat' index 5 using 5:3 with points pt 7 ps 0.8 lc rgb '#d62728' title 'AUTO', \
     '' index 6 using 5:3 with lines lw 2 lc rgb '#d62728' notitle, \
     '/work/main/benchmarks/results/work_precision_long.dat' index 10 using 5:3 with points pt 7 ps 0.8 lc rgb '#2ca02c' title 'naive', \
     '' index 11 using 5:3 with lines lw 2 lc rgb '#2ca02c' notitle, \
     '/work/main/benchmarks/results/work_precision_long.dat' index 15 using 5:3 with points pt 7 ps 0.8 lc rgb '#9467bd' title 'buckle-P2', \
     '' index 16 using 5:3 with lines lw 2 lc rgb '#9467bd' notitle
set xlabel 'branch error (max distance to the true curve)'
set ylabel 'wall time per run [ms]'
plot '/work/main/benchmarks/results/work_precision_long.dat' index 0 using 6:3 with points pt 7 ps 0.8 lc rgb '#1f77b4' title 'buckle', \
     '' index 2 using 6:3 with lines lw 2 lc rgb '#1f77b4' notitle, \
     '/work/main/benchmarks/results/work_precision_long.dat' index 5 using 6:3 with points pt 7 ps 0.8 lc rgb '#d62728' title 'AUTO', \
     '' index 7 using 6:3 with lines lw 2 lc rgb '#d62728' notitle, \
     '/work/main/benchmarks/results/work_precision_long.dat' index 10 using 6:3 with points pt 7 ps 0.8 lc rgb '#2ca02c' title 'naive', \
     '' index 12 using 6:3 with lines lw 2 lc rgb '#2ca02c' notitle, \
     '/work/main/benchmarks/results/work_precision_long.dat' index 15 using 6:3 with points pt 7 ps 0.8 lc rgb '#9467bd' title 'buckle-P2', \
     '' index 17 using 6:3 with lines lw 2 lc rgb '#9467bd' notitle
set xlabel 'special-point error |dFx|'
set ylabel 'CPU time per run [ms]'
plot '/work/main/benchmarks/results/work_precision_long.dat' index 0 using 5:4 with points pt 7 ps 0.8 lc rgb '#1f77b4' title 'buckle', \
     '' index 3 using 5:4 with lines lw 2 lc rgb '#1f77b4' notitle, \
     '/work/main/benchmarks/results/work_precision_long.dat' index 5 using 5:4 with points pt 7 ps 0.8 lc rgb '#d62728' title 'AUTO', \
     '' index 8 using 5:4 with lines lw 2 lc rgb '#d62728' notitle, \
     '/work/main/benchmarks/results/work_precision_long.dat' index 10 using 5:4 with points pt 7 ps 0.8 lc rgb '#2ca02c' title 'naive', \
     '' index 13 using 5:4 with lines lw 2 lc rgb '#2ca02c' notitle, \
     '/work/main/benchmarks/results/work_precision_long.dat' index 15 using 5:4 with points pt 7 ps 0.8 lc rgb '#9467bd' title 'buckle-P2', \
     '' index 18 using 5:4 with lines lw 2 lc rgb '#9467bd' notitle
set xlabel 'branch error (max distance to the true curve)'
set ylabel 'CPU time per run [ms]'
plot '/work/main/benchmarks/results/work_precision_long.dat' index 0 using 6:4 with points pt 7 ps 0.8 lc rgb '#1f77b4' title 'buckle', \
     '' index 4 using 6:4 with lines lw 2 lc rgb '#1f77b4' notitle, \
     '/work/main/benchmarks/results/work_precision_long.dat' index 5 using 6:4 with points pt 7 ps 0.8 lc rgb '#d62728' title 'AUTO', \
     '' index 9 using 6:4 with lines lw 2 lc rgb '#d62728' notitle, \
     '/work/main/benchmarks/results/work_precision_long.dat' index 10 using 6:4 with points pt 7 ps 0.8 lc rgb '#2ca02c' title 'naive', \
     '' index 14 using 6:4 with lines lw 2 lc rgb '#2ca02c' notitle, \
     '/work/main/benchmarks/results/work_precision_long.dat' index 15 using 6:4 with points pt 7 ps 0.8 lc rgb '#9467bd' title 'buckle-P2', \
     '' index 19 using 6:4 with lines lw 2 lc rgb '#9467bd' notitle
unset multiplot
