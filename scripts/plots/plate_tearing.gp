# Plots the history of examples/plate_tearing as PNG (gnuplot, Debian package
# gnuplot-nox):  gnuplot -c scripts/plots/plate_tearing.gp [history.csv] [out.png]
# Crosshead force and crack advance against the crosshead displacement
# (paper Figs. 26 and 27).
input = ARGC >= 1 ? ARG1 : "plate_tearing.csv"
output = ARGC >= 2 ? ARG2 : "plate_tearing.png"
set datafile separator ","
set terminal pngcairo size 1000,420 noenhanced
set output output
set multiplot layout 1, 2
set xlabel "crosshead displacement [mm]"
set grid
set ylabel "crosshead force P [kN]"
plot input using (column("stroke [m]")*1e3):(column("P_crosshead [N]")*1e-3) with lines title "P"
set ylabel "crack advance [mm]"
plot input using (column("stroke [m]")*1e3):(column("crack_advance [m]")*1e3) with lines title "crack"
unset multiplot
