# Succ of every evaluated checkpoint (eval_curves.csv: 10 episodes x 10 s per
# view from the fit's starts) against samples and against training wall
# time, one line per variant. From the repository root:
#   gnuplot docs/experiments/walk2d_fast/plot_eval_curves.gp
set terminal pngcairo size 1400,520 font ",11" noenhanced
set output "docs/images/samples_to_learn_eval.png"
set datafile separator ","
set key bottom right
set grid
set yrange [0:1]
set ytics 0.1
data = "docs/experiments/walk2d_fast/eval_curves.csv"
# The floor-6e-5 runs were trained on slower machines, their wall time
# shared: they are drawn against samples only (the first panel).
variants = "fast fast_floor3e-5 per_thread_floor3e-5_seed1 per_thread_floor3e-5_seed2 floor6e-5_bf16_seed1 floor6e-5_bf16_seed2 floor6e-5_fp32_seed1 floor6e-5_bf16_timed_zen5 exact_mean_bf16_timed_zen5"
wall_variants = 4
title_of(i) = i == 1 ? "batched, floor 2e-5, seed 1" : \
              i == 2 ? "batched, floor 3e-5, seed 1" : \
              i == 3 ? "per-thread, floor 3e-5, seed 1" : \
              i == 4 ? "per-thread, floor 3e-5, seed 2" : \
              i == 5 ? "per-thread, floor 6e-5, seed 1" : \
              i == 6 ? "per-thread, floor 6e-5, seed 2" : \
              i == 7 ? "per-thread, floor 6e-5, seed 1, float32" : \
              i == 8 ? "floor 6e-5, bf16, timed on a Zen 5" : \
                       "floor 6e-5, bf16 with a float32 mean, Zen 5"
set multiplot layout 1,2 title "Walk from 2D only (configs/walk2d_fast.yaml variants): Succ of each checkpoint, 40 rollouts"
set xlabel "samples (millions)"
set ylabel "Succ"
plot for [i=1:words(variants)] data using (strcol(1) eq word(variants, i) ? $2 / 1e6 : NaN):4 \
     with linespoints title title_of(i), 0.9 with lines dashtype 2 lc rgb "gray" notitle
set xlabel "training wall time (min)"
set arrow from 30, 0 to 30, 1 nohead dashtype 2 lc rgb "black"
plot for [i=1:wall_variants] data using (strcol(1) eq word(variants, i) ? $3 / 60 : NaN):4 \
     with linespoints title title_of(i), 0.9 with lines dashtype 2 lc rgb "gray" notitle
unset multiplot

# The critic's size and the epochs (sessions 36-38, one core each on the
# Zen 5, against the shipped config's three runs): against samples only,
# since their wall times were shared with other runs and pauses.
set output "docs/images/samples_to_learn_critic.png"
set terminal pngcairo size 1000,620 font ",11" noenhanced
unset arrow
critic_variants = "floor6e-5_bf16_seed1 floor6e-5_bf16_seed2 floor6e-5_bf16_timed_zen5 epochs2_floor9e-5_zen5_1core epochs2_floor9e-5_critic256_zen5_1core critic1024x512_zen5_1core critic1024x512_seed2_zen5_1core critic1024x512_epochs2_floor9e-5_zen5_1core critic1024x512_epochs2_floor9e-5_seed2_zen5_1core critic1024x256_zen5_1core critic1024x256_seed2_zen5_1core"
critic_title(i) = i == 1 ? "shipped, seed 1" : \
                  i == 2 ? "shipped, seed 2" : \
                  i == 3 ? "shipped, timed on the Zen 5" : \
                  i == 4 ? "2 epochs, floor 9e-5" : \
                  i == 5 ? "critic 256/256, 2 epochs, floor 9e-5" : \
                  i == 6 ? "critic 1024/512, seed 1" : \
                  i == 7 ? "critic 1024/512, seed 2" : \
                  i == 8 ? "critic 1024/512, 2 epochs, floor 9e-5, seed 1" : \
                  i == 9 ? "critic 1024/512, 2 epochs, floor 9e-5, seed 2" : \
                  i == 10 ? "critic 1024/256, seed 1" : \
                            "critic 1024/256, seed 2"
set title "Walk from 2D only: the critic's size and the epochs (Succ of each checkpoint, 40 rollouts from the fit's starts and cameras)"
set xlabel "samples (millions)"
set xrange [4:16]
plot for [i=1:words(critic_variants)] data using (strcol(1) eq word(critic_variants, i) ? $2 / 1e6 : NaN):4 \
     with linespoints lw (i <= 3 ? 2.5 : 1.2) title critic_title(i), 0.9 with lines dashtype 2 lc rgb "gray" notitle

# The asymmetric critic (session 39: env.critic_observes_3d, one core each on
# the Zen 5, and a timed 2-core run) against the shipped config's three runs.
set output "docs/images/samples_to_learn_asymmetric.png"
asym_variants = "floor6e-5_bf16_seed1 floor6e-5_bf16_seed2 floor6e-5_bf16_timed_zen5 critic3d_seed1_zen5_1core critic3d_seed2_zen5_1core critic3d_timed_zen5"
asym_title(i) = i == 1 ? "shipped, seed 1" : \
                i == 2 ? "shipped, seed 2" : \
                i == 3 ? "shipped, timed on the Zen 5" : \
                i == 4 ? "asymmetric critic, seed 1" : \
                i == 5 ? "asymmetric critic, seed 2" : \
                         "asymmetric critic, timed on the Zen 5"
set title "Walk from 2D only: the asymmetric critic (Succ of each checkpoint, 40 rollouts from the fit's starts and cameras)"
plot for [i=1:words(asym_variants)] data using (strcol(1) eq word(asym_variants, i) ? $2 / 1e6 : NaN):4 \
     with linespoints lw (i <= 3 ? 1.2 : 2.5) title asym_title(i), 0.9 with lines dashtype 2 lc rgb "gray" notitle
