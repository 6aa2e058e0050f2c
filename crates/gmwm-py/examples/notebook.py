"""A notebook session, cell by cell: simulate a gyroscope of known noise, look at its wavelet
variance, select a model by WIC, fit it, calibrate a three-axis IMU and read the table a
navigation filter needs. Run as a script: `python examples/notebook.py`."""

import numpy as np

import gmwm

# %% A 100 Hz gyroscope: white noise N = 1e-3 rad/s/√Hz, random walk K = 1e-4 rad/s²/√Hz,
# and a Gauss-Markov bias with a 20 s correlation time (docs/methods.md §14.2: sigma2 = N² f,
# gamma2 = K² / f).
f = 100.0
truth = "GM(beta=0.05, sigma2_gm=1e-8)+WN(sigma2=1e-4)+RW(gamma2=1e-10)"
x = gmwm.simulate(truth, n=1 << 16, freq=f, seed=42)

# %% Its wavelet variance, as a table.
wv = gmwm.wv(x, freq=f)
print(wv.to_dataframe().head())

# %% Which model? Every sub-model of the full one is a candidate.
sel = gmwm.select(x, freq=f, model="2*AR1()+WN()+RW()", bootstrap=20, G=2000)
print("selected:", sel.selected())
print(sel.to_dataframe().head())

# %% The fit of the selected model, with intervals.
fit = gmwm.fit(x, freq=f, model=sel.selections[0]["selected"], G=2000, inference=True)
print(fit.to_dataframe())

# %% A three-axis gyroscope, calibrated: N, B, K per axis, in SI with intervals.
imu = np.vstack([gmwm.simulate(truth, n=1 << 16, freq=f, seed=s) for s in (1, 2, 3)])
cal = gmwm.calibrate(imu, freq=f, names=["gyro_x", "gyro_y", "gyro_z"], units=["rad/s"] * 3,
                     model="2*AR1()+WN()+RW()", bootstrap=20, G=2000)
table = cal.to_dataframe()
print(table[["axis", "model", "noise_density", "random_walk", "explains_wv"]])
assert np.allclose(table["noise_density"], 1e-3, rtol=0.1), table["noise_density"]

# %% What a Kalibr-style filter takes (the worst axis of the triad).
print(cal.exported[0]["noise"])
