set terminal png size 900,600
set output '/work/main/benchmarks/results/work_precision.png'
set logscale xy
set format x '10^{%L}'
set format y '10^{%L}'
set grid
set xlabel 'error'
set ylabel 'time per run [ms]'
set title 'buckle work-precision, n = 3 (errors of 0 shown as 1e-17)'
set key top right
plot '/work/main/benchmarks/results/work_precision.dat' index 0 using 6:5 with points pt 7 title '(a) BP1, BP2 vs eq 17', \
     '' index 1 using 6:5 with points pt 5 title '(b) fold vs tight reference', \
     '' index 2 using 6:5 with points pt 9 title '(c) U-branch vs reference curve'
