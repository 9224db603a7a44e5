load('session.mat');  % session, iterations, black_boxes
last = iterations(end);
fprintf('%d iterations, last RMS %.4f deg\n', numel(iterations), last.rms_deg);
box = black_boxes(end);
fprintf('black box: %s, last state %s\n', box.fault, box.ticks.state{end});
% plot(last.samples.time_s, [last.samples.angle_setpoint_deg, last.samples.angle_deg])
