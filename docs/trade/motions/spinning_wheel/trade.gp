set terminal pngcairo size 900,560 font ',11' noenhanced
set output 'trade.png'
set logscale xy
set xlabel 'time per frame, cut and .glb export, one thread (milliseconds)'
set ylabel 'measured two-sided error / largest object size'
set grid
set key top right
set title 'apparent trade: error against time'
plot 'trade.dat' index 0 using 1:2 with points pt 7 ps 2 title 'vertex mode', \
     'trade.dat' index 1 using 1:2 with linespoints lw 2 pt 5 title 'uniform subdivision (levels 1..k)', \
     'trade.dat' index 2 using 1:2 with linespoints lw 2 pt 9 title '--tolerance T (adaptive)'
