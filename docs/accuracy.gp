set terminal pngcairo size 900,560 font ",11"
set output '/work/main/docs/accuracy.png'
set logscale xy
set xlabel 'time per frame (microseconds)'
set ylabel 'measured maximum error / object size'
set grid
set key top right
set title 'apparent: accuracy against time (first point of each line: vertex mode)'
plot '/work/main/docs/accuracy_flanges.dat' using 1:2 with linespoints lw 2 pt 7 title 'flanges (relativistic)', \
     '/work/main/docs/accuracy_sphere.dat' using 1:2 with linespoints lw 2 pt 5 title 'sphere at 0.9c (relativistic)'
