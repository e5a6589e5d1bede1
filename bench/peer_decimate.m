% Peer of bench_signal: Octave's decimate (signal package, FIR) of each raw channel.
% Usage: octave-cli peer_decimate.m IN OUT REPEATS N FACTOR
% Writes the decimated channels (float64, one after another, without Octave's delay) to OUT,
% the taps of the anti-alias filter decimate used (fir1(30, 1/FACTOR)) to OUT.taps, and prints
% one JSON line.
pkg load signal
args = argv();
% FLEXARM_BENCH_CLOCK=cpu: CPU time instead of the wall clock, as the bench programs do.
if strcmp(getenv("FLEXARM_BENCH_CLOCK"), "cpu") clock_now = @() cputime(); else clock_now = @() time(); end
src = args{1}; dst = args{2};
reps = str2double(args{3}); n = str2double(args{4}); q = str2double(args{5});
f = fopen(src, "r"); x = fread(f, Inf, "double"); fclose(f);
x = reshape(x, n, []);
times = zeros(reps, 1);
for r = 1:reps
  t0 = clock_now();
  out = [];
  for c = 1:columns(x)
    out = [out; decimate(x(:, c), q, "fir")];
  end
  times(r) = clock_now() - t0;
end
% Octave's FIR decimation is causal: its output lags by half the filter (fir1 of order 30,
% 15 samples). For the comparison (not timed) that delay is removed.
b = fir1(30, 1 / q);
aligned = [];
for c = 1:columns(x)
  y = fftfilt(b, [x(:, c); zeros(15, 1)]);
  aligned = [aligned; y(16:q:end)];
end
f = fopen(dst, "w"); fwrite(f, aligned, "double"); fclose(f);
f = fopen([dst ".taps"], "w"); fwrite(f, b, "double"); fclose(f);
printf("{\"name\": \"decimate\", \"seconds\": %.9g}\n", median(times));
