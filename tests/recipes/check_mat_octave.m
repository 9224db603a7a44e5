% Checks that Octave reads every field of a bellows MAT export with the right values.
% Usage: octave-cli --no-gui -q --no-window-system --no-history check_mat_octave.m FILE.mat EXPECTED.json
% EXPECTED.json mirrors the MAT file's variables (see check_mat_scipy.py). Numbers agree to the
% last bit the JSON reader keeps (Octave's jsondecode may round the 17th digit: 2 eps).
1;

function fail(where, why)
  printf('%s: %s\n', where, why);
  exit(1);
end

function compare(got, want, where)
  if isstruct(want) && numel(want) == 1 && !isstruct(got)
    fail(where, 'expected a struct');
  end
  if isstruct(want)
    if numel(got) != numel(want)
      fail(where, sprintf('%d structs, expected %d', numel(got), numel(want)));
    end
    if !isempty(setxor(fieldnames(got), fieldnames(want)))
      fail(where, ['fields differ: ' strjoin(setxor(fieldnames(got), fieldnames(want))', ', ')]);
    end
    names = fieldnames(want);
    for i = 1:numel(want)
      for f = 1:numel(names)
        compare(got(i).(names{f}), want(i).(names{f}), sprintf('%s(%d).%s', where, i, names{f}));
      end
    end
  elseif iscell(want)
    if !iscellstr(got) || numel(got) != numel(want) || !all(strcmp(got(:), want(:)))
      fail(where, 'names differ');
    end
  elseif ischar(want)
    if isempty(want) && isempty(got)
      % an empty char array: 0x0 or 1x0, both ''
    elseif !ischar(got) || !strcmp(got, want)
      fail(where, sprintf('text "%s" differs from "%s"', num2str(got), want));
    end
  else
    a = double(got(:)); b = double(want(:));
    if numel(a) != numel(b)
      fail(where, sprintf('%d numbers, expected %d', numel(a), numel(b)));
    end
    same = (isnan(a) & isnan(b)) | (a == b) | (abs(a - b) <= 2 * eps(abs(b)));
    if !all(same)
      k = find(!same, 1);
      fail(sprintf('%s[%d]', where, k - 1), sprintf('%.17g differs from %.17g', a(k), b(k)));
    end
  end
end

args = argv();
got = load(args{1});
expected = jsondecode(fileread(args{2}));
names = fieldnames(expected);
for v = 1:numel(names)
  if !isfield(got, names{v})
    fail(names{v}, 'variable missing');
  end
  compare(got.(names{v}), expected.(names{v}), names{v});
end
printf('octave read %d variables; every field agrees\n', numel(names));
