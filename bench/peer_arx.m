% Peer of bench_ident_poly: Octave's arx (control package) on the same data.
% Usage: octave-cli peer_arx.m PROBLEM_JSON REPEATS
% Prints one JSON line: name "arx", seconds (median), loss, theta [a1..a_na b1..b_nb].
pkg load control
args = argv();
% FLEXARM_BENCH_CLOCK=cpu: CPU time instead of the wall clock, as the bench programs do.
if strcmp(getenv("FLEXARM_BENCH_CLOCK"), "cpu") clock_now = @() cputime(); else clock_now = @() time(); end
p = jsondecode(fileread(args{1}));
reps = str2double(args{2});
o = p.orders;
na = o(1); nb = o(2); nk = o(6);
u = p.u(:); y = p.y(:);
dat = iddata(y, u, 1);
times = zeros(reps, 1);
for r = 1:reps
  t0 = clock_now();
  sys = arx(dat, "na", na, "nb", nb, "nk", nk - 1);  % Octave's B starts at q^-1 when nk = 0
  times(r) = clock_now() - t0;
end
[b, a] = filtdata(sys);  % numerator, denominator in q^-1
a = a{1}; b = b{1};
theta = [a(2:na+1), b(nk+1:nk+nb)];
first = max(na, nb + nk - 1);
e = filter(a, 1, y) - filter(b, 1, u);
e = e(first+1:end);
printf("{\"name\": \"arx\", \"seconds\": %.9g, \"loss\": %.17g, \"theta\": [%s]}\n", ...
       median(times), mean(e.^2), strjoin(arrayfun(@(v) sprintf("%.17g", v), theta, "UniformOutput", false), ", "));
