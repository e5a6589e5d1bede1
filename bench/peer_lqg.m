% Peer of bench_lqg: one LQG slider move with Octave's control package, as peer_lqg.py does
% it with SciPy: care for the regulator and the Kalman filter (with the arm-load state x5),
% freqresp of F_y G and G_0 on FlexArm's grid, |S| and |T|, pole lists, and the disturbance
% steps of Figure 8.3 by lsim (zero-order hold, 1 ms, 3 s).
% Usage: octave-cli peer_lqg.m GRID_FILE REPETITIONS
% Prints one JSON line: name "lqg", seconds (median), max_s and peak_arm for case (ii).
pkg load control
args = argv();
% FLEXARM_BENCH_CLOCK=cpu: CPU time instead of the wall clock, as the bench programs do.
if strcmp(getenv("FLEXARM_BENCH_CLOCK"), "cpu") clock_now = @() cputime(); else clock_now = @() time(); end
w = load(args{1});
reps = str2double(args{2});
Jm = 0.0043; Ja = 0.0762; fm = 0.02; fa = 0.005; k = 43.0; d = 0.05;
A = [0 1 0 0; -k/Jm -(d+fm)/Jm k/Jm d/Jm; 0 0 0 1; k/Ja d/Ja -k/Ja -(d+fa)/Ja];
B = [0; 1/Jm; 0; 0]; Bv = [0; 0; 0; 1/Ja]; C = [1 0 0 0];
Ab = [A Bv; zeros(1, 5)]; Bb = [B; 0]; Cb = [C 0];

function [ms, peak] = slider_move(A, B, Bv, C, Ab, Bb, Cb, r2, w)
  X = care(A, B, diag([100 1 0 0]), 1);
  L = B' * X;
  X12 = (A - B * L)' \ (-X * Bv);
  Lb = [L, B' * X12];
  P = care(Ab', Cb', diag([0 0 0 0 1]), r2);
  K = P * Cb' / r2;
  Ar = Ab - Bb * Lb - K * Cb;
  poles = {eig(A), eig(Ar)};
  Fy = ss(Ar, K, Lb, 0);
  G = ss(A, B, C, 0);
  loop = squeeze(freqresp(Fy, w)) .* squeeze(freqresp(G, w));
  g0 = squeeze(freqresp(ss(Ab, Bb, Lb, 0), w));
  S = 1 ./ abs(1 + loop);
  T = abs(loop) .* S;
  Acl = [A, -B * Lb; K * C, Ar];
  poles{end + 1} = eig(Acl);
  Bcl = [B Bv; zeros(5, 2)];
  t = (0:3000)' * 1e-3;
  u = [ones(size(t)), double(t >= 1 - 1e-12)];
  x = lsim(ss(Acl, Bcl, [0 0 1 0 zeros(1, 5)], zeros(1, 2)), u, t);
  ms = max(S);
  peak = max(abs(x));
end

times = zeros(reps, 1);
for i = 1:reps
  r2 = 10 ^ (-8 + 2 * mod(i - 1, 20) / 19);
  t0 = clock_now();
  slider_move(A, B, Bv, C, Ab, Bb, Cb, r2, w);
  times(i) = clock_now() - t0;
end
[ms, peak] = slider_move(A, B, Bv, C, Ab, Bb, Cb, 1e-8, w);
printf("{\"name\": \"lqg\", \"seconds\": %.9g, \"max_s\": %.12g, \"peak_arm\": %.12g}\n", ...
       median(times), ms, peak);
