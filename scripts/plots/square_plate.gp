# Plots the history of examples/square_plate as PNG (gnuplot, Debian package
# gnuplot-nox):  gnuplot -c scripts/plots/square_plate.gp [history.csv] [out.png]
# Centre deflection w_A (paper Figs. 8, 11, 15, 22) and, for --case fracture,
# the crack length (Fig. 21).
input = ARGC >= 1 ? ARG1 : "square_plate.csv"
output = ARGC >= 2 ? ARG2 : "square_plate.png"
set datafile separator ","
set terminal pngcairo size 1000,420 noenhanced
set output output
stats input using 1 nooutput
fracture = system(sprintf("head -1 '%s' | grep -c crack_length", input)) + 0
set multiplot layout 1, (fracture ? 2 : 1)
set xlabel "t [ms]"
set ylabel "centre deflection w_A [mm]"
set grid
plot input using ($1*1e3):(-column("w_A [m]")*1e3) with lines title "point A"
if (fracture) {
  set ylabel "crack length [m] (all cracks)"
  plot input using ($1*1e3):(column("crack_length [m]")) with lines title "crack length"
}
unset multiplot
