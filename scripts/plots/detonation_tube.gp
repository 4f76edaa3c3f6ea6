# Plots the crack tips of examples/detonation_tube as PNG (gnuplot, Debian
# package gnuplot-nox):  gnuplot -c scripts/plots/detonation_tube.gp [crack_tips.csv] [out.png]
# Rear and front crack-tip speeds against time (paper Fig. 32).
input = ARGC >= 1 ? ARG1 : "detonation_tube.csv"
output = ARGC >= 2 ? ARG2 : "detonation_tube.png"
set datafile separator ","
set terminal pngcairo size 1000,420 noenhanced
set output output
set multiplot layout 1, 2
set xlabel "t [µs]"
set grid
set ylabel "rear crack speed [m/s]"
plot input using ($1*1e6):(column("rear_speed [m/s]")) with lines title "rear"
set ylabel "front crack speed [m/s]"
plot input using ($1*1e6):(column("front_speed [m/s]")) with lines title "front"
unset multiplot
