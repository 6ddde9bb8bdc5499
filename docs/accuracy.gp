set terminal pngcairo size 1000,620 font ',11' noenhanced
set output 'accuracy.png'
set logscale xy
set xlabel 'output triangles per frame'
set ylabel 'measured two-sided error / size'
set grid
set key outside right
set title 'apparent: error against triangles (solid: --tolerance, dashed: uniform subdivision)'
plot 'accuracy_flanges.dat' index 2 using 1:2 with linespoints lw 2 pt 7 lc 1 title 'flanges: tolerance', \
     'accuracy_flanges.dat' index 1 using 1:2 with linespoints lw 1 dt 2 pt 6 lc 1 title 'flanges: uniform', \
     'accuracy_box_near.dat' index 2 using 1:2 with linespoints lw 2 pt 7 lc 2 title 'box_near: tolerance', \
     'accuracy_box_near.dat' index 1 using 1:2 with linespoints lw 1 dt 2 pt 6 lc 2 title 'box_near: uniform', \
     'accuracy_sphere320.dat' index 2 using 1:2 with linespoints lw 2 pt 7 lc 3 title 'sphere320: tolerance', \
     'accuracy_sphere320.dat' index 1 using 1:2 with linespoints lw 1 dt 2 pt 6 lc 3 title 'sphere320: uniform', \
     'accuracy_plate.dat' index 2 using 1:2 with linespoints lw 2 pt 7 lc 4 title 'plate: tolerance', \
     'accuracy_plate.dat' index 1 using 1:2 with linespoints lw 1 dt 2 pt 6 lc 4 title 'plate: uniform', \
     'accuracy_sphere20480.dat' index 2 using 1:2 with linespoints lw 2 pt 7 lc 5 title 'sphere20480: tolerance', \
     'accuracy_sphere20480.dat' index 1 using 1:2 with linespoints lw 1 dt 2 pt 6 lc 5 title 'sphere20480: uniform'
