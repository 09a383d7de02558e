#!/usr/bin/env python3
"""Writes the phyphox and GetSensorData fixtures of tests/data/loggers from the formats'
documentation (SOURCE.md): a 30 s walk north at 1.25 m/s, 1.8 Hz steps, phone held flat,
deterministic (no random numbers). Run from this folder; the output is committed."""
import math, os

G = 9.80665
T = 30.0
LAT0, LON0, H0 = 47.4072629, 8.5104485, 586.5          # a start near the shared ETHZ walk
M_PER_DEG_LAT = 111_132.0
M_PER_DEG_LON = 111_320.0 * math.cos(math.radians(LAT0))
P0_HPA = 947.77

def acc(t):   # phone flat, screen up: +g on z, 1.8 Hz vertical bounce, small sway on x
    return (0.35 * math.sin(2 * math.pi * 0.9 * t), 0.6 * math.sin(2 * math.pi * 1.8 * t + 0.4),
            G + 1.8 * math.sin(2 * math.pi * 1.8 * t))
def gyr(t):
    return (0.05 * math.sin(2 * math.pi * 1.8 * t), 0.04 * math.cos(2 * math.pi * 0.9 * t), 0.02 * math.sin(0.3 * t))
def mag(t):   # walking north, flat: field north (+y) and down (-z)
    return (1.2 + 0.3 * math.sin(0.2 * t), 21.5, -42.0)
def pres(t):
    return P0_HPA - 0.004 * t
def pos(t):
    n = 1.25 * t
    return LAT0 + n / M_PER_DEG_LAT, LON0, H0 + 0.03 * t

def jfmt(x, dec='.'):
    """Java DecimalFormat "0.000000000E0" (phyphox DataExport.java)."""
    if x == 0:
        s = "0.000000000E0"
    else:
        e = int(math.floor(math.log10(abs(x))))
        m = x / 10 ** e
        if round(abs(m), 9) >= 10:
            e += 1
            m = x / 10 ** e
        s = "%.9fE%d" % (m, e)
    return s.replace('.', dec)

# ---- phyphox: "Simple experiment" export (set per sensor), CSV comma / decimal point ------
def phyphox(folder, sep=',', dec='.'):
    os.makedirs(os.path.join(folder, 'meta'), exist_ok=True)
    q = lambda s: '"' + s + '"'
    # one pause: recording 0..12 s, paused 20 s of wall time, then 12..30 s
    start_unix = 1710000000.250
    pause_exp, pause_wall = 12.0, 20.0
    def rows(name, header, rate, f):
        with open(os.path.join(folder, name), 'w', newline='') as out:
            out.write(sep.join(q(h) for h in header) + '\n')
            n = int(T * rate)
            for i in range(n):
                t = (i + 0.37) / rate
                out.write(sep.join(jfmt(v, dec) for v in (t,) + tuple(f(t))) + '\n')
    rows('Accelerometer.csv', ["Time (s)", "Acceleration x (m/s^2)", "Acceleration y (m/s^2)", "Acceleration z (m/s^2)"], 100, acc)
    rows('Gyroscope.csv', ["Time (s)", "Gyroscope x (rad/s)", "Gyroscope y (rad/s)", "Gyroscope z (rad/s)"], 100, gyr)
    rows('Magnetometer.csv', ["Time (s)", "Magnetic field x (\u00b5T)", "Magnetic field y (\u00b5T)", "Magnetic field z (\u00b5T)"], 50, mag)
    rows('Pressure.csv', ["Time (s)", "Pressure (hPa)"], 5, lambda t: (pres(t),))
    rows('Location.csv', ["Time (s)", "Latitude (\u00b0)", "Longitude (\u00b0)", "Height (m)", "Velocity (m/s)",
                          "Direction (\u00b0)", "Horizontal Accuracy (m)", "Vertical Accuracy (m)"], 1,
         lambda t: pos(t) + (1.25, 0.0, 4.5, 3.0))
    rows('Linear Acceleration.csv', ["Time (s)", "Linear Acceleration x (m/s^2)", "Linear Acceleration y (m/s^2)",
                                     "Linear Acceleration z (m/s^2)"], 10, lambda t: (0.0, 0.1, 0.2))
    with open(os.path.join(folder, 'meta', 'device.csv'), 'w', newline='') as out:
        out.write(sep.join([q("property"), q("value")]) + '\n')
        for k, v in [("version", "1.1.16"), ("build", "1011601"), ("fileFormat", "1.18"), ("deviceModel", "Pixel 6a"),
                     ("deviceBrand", "google"), ("deviceBoard", "bluejay"), ("deviceManufacturer", "Google"),
                     ("deviceBaseOS", ""), ("deviceCodename", "REL"), ("deviceRelease", "14"),
                     ("accelerometer Name", "LSM6DSV Accelerometer"), ("accelerometer Resolution", "0.0047856453")]:
            out.write(sep.join([q(k), q(v)]) + '\n')
    with open(os.path.join(folder, 'meta', 'time.csv'), 'w', newline='') as out:
        out.write(sep.join(q(h) for h in ["event", "experiment time", "system time", "system time text"]) + '\n')
        for ev, x, w in [("START", 0.0, start_unix), ("PAUSE", pause_exp, start_unix + pause_exp),
                         ("START", pause_exp, start_unix + pause_exp + pause_wall),
                         ("PAUSE", T, start_unix + T + pause_wall)]:
            wall = ("%.3f" % w).replace('.', dec)
            out.write(sep.join([q(ev), jfmt(x, dec), wall, q("2024-03-09 17:00:%06.3f UTC+01:00" % (w - 1710000000 + 0.0))]) + '\n')

phyphox('phyphox-walk')
phyphox('phyphox-walk-semicolon', sep=';', dec=',')

# ---- GetSensorData (IPIN logfile, version 2.x header) ----------------------------------------
def gsd(path):
    lines = []
    hdr = ["% LogFile created by the 'GetSensorData' App for Android.",
           "% Date of creation: Sat Mar 09 17:00:00 CET 2024",
           "% Developed by LOPSI research group at CAR-CSIC, Spain (http://www.car.upm-csic.es/lopsi)",
           "% Version 2.1 January 2018",
           "% The 'GetSensorData' program stores information from Smartphone/Tablet internal sensors (Accelerometers, Gyroscopes, Magnetometers, Pressure, Ambient Light, Orientation, Sound level, GPS/GNSS position, WiFi RSS, Cellular/GSM/3G signal strength,...) and also from external devices (e.g. RFCode RFID reader, XSens IMU, LPMS-B IMU or MIMU22BT)",
           "%", "% Phone used for this logfile:",
           "% Manufacturer:            \tGoogle", "% Model:                   \tPixel 6a",
           "% API Android version:     \t34", "% Android version Release: \t14", "%", "% LogFile Data format:",
           "% Accelerometer data: \t'ACCE;AppTimestamp(s);SensorTimestamp(s);Acc_X(m/s^2);Acc_Y(m/s^2);Acc_Z(m/s^2);Accuracy(integer)'",
           "% Gyroscope data:     \t'GYRO;AppTimestamp(s);SensorTimestamp(s);Gyr_X(rad/s);Gyr_Y(rad/s);Gyr_Z(rad/s);Accuracy(integer)'",
           "% Magnetometer data:  \t'MAGN;AppTimestamp(s);SensorTimestamp(s);Mag_X(uT);;Mag_Y(uT);Mag_Z(uT);Accuracy(integer)'",
           "% Pressure data:      \t'PRES;AppTimestamp(s);SensorTimestamp(s);Pres(mbar);Accuracy(integer)'",
           "% Light data:         \t'LIGH;AppTimestamp(s);SensorTimestamp(s);Light(lux);Accuracy(integer)'",
           "% Orientation data:   \t'AHRS;AppTimestamp(s);SensorTimestamp(s);PitchX(deg);RollY(deg);YawZ(deg);Quat(2);Quat(3);Quat(4);Accuracy(int)'",
           "% GNSS/GPS data:      \t'GNSS;AppTimestamp(s);SensorTimeStamp(s);Latit(deg);Long(deg);Altitude(m);Bearing(deg);Accuracy(m);Speed(m/s);SatInView;SatInUse'",
           "% WIFI data:          \t'WIFI;AppTimestamp(s);SensorTimeStamp(s);Name_SSID;MAC_BSSID;Frequency;RSS(dBm);'",
           "% POSI Reference:    \t\t'POSI;Timestamp(s);Counter;Latitude(degrees); Longitude(degrees);floor ID(0,1,2..4);Building ID(0,1,2..3);'",
           "% ",
           "% Note that there are two timestamps: ",
           "%  -'AppTimestamp' is set by the Android App as data is read. It is not representative of when data is actually captured by the sensor (but has a common time reference for all sensors)",
           "%  -'SensorTimestamp' is set by the sensor itself (the delta_time=SensorTimestamp(k)-SensorTimestamp(k-1) between two consecutive samples is an accurate estimate of the sampling interval). This timestamp is better for integrating inertial data. "]
    boot = 84512.3405     # sensor clock (s since boot) at the app's t = 0
    ev = []
    def add(t_sensor, delay, text):
        ev.append((t_sensor + delay, text))
    for i in range(int(T * 50)):   # 50 Hz IMU; the app reads each sample 4-9 ms late
        t = 0.012 + i / 50.0
        d = 0.004 + 0.005 * ((i * 7) % 11) / 10.0
        a, g, m = acc(t), gyr(t), mag(t)
        add(t, d, "ACCE;%.3f;%.3f;%.5f;%.5f;%.5f;3" % (t + d, boot + t, *a))
        add(t + 0.001, d, "GYRO;%.3f;%.3f;%.5f;%.5f;%.5f;3" % (t + 0.001 + d, boot + t + 0.001, *g))
        add(t + 0.002, d, "MAGN;%.3f;%.3f;%.5f;%.5f;%.5f;3" % (t + 0.002 + d, boot + t + 0.002, *m))
        if i % 5 == 0:   # rotation vector of a phone flat, screen up, top to the north: identity
            yaw = 2.0 * math.sin(0.1 * t)                       # degrees of wobble
            qz = math.sin(math.radians(-yaw) / 2)
            add(t + 0.003, d, "AHRS;%.3f;%.3f;%.6f;%.6f;%.6f;%.8f;%.8f;%.8f;3" %
                (t + 0.003 + d, boot + t + 0.003, 0.0, 0.0, yaw, 0.0, 0.0, qz))
    for i in range(int(T * 5)):
        t = 0.05 + i / 5.0
        add(t, 0.006, "PRES;%.3f;%.3f;%.4f;0" % (t + 0.006, boot + t, pres(t)))
        add(t, 0.006, "LIGH;%.3f;%.3f;%.1f;0" % (t + 0.006, boot + t, 310.0))
    for i in range(int(T)):
        t = 0.9 + i
        la, lo, h = pos(t)
        add(t, 0.020, "GNSS;%.3f;%.3f;%.6f;%.6f;%.3f;%.3f;%.1f;%.1f;%d;%d" % (t + 0.020, 1710000000.9 + i, la, lo, h, 0.0, 4.0, 1.25, 23, 17))
        add(t, 0.050, "WIFI;%.3f;%.3f;%s;%s;%d;%d" % (t + 0.050, 1710000000.9 + i, "eduroam", "00:1a:2b:3c:4d:5e", 2437, -67))
    for k, t in enumerate([0.5, 10.5, 20.5, 29.5]):
        la, lo, _ = pos(t)
        add(t, 0.0, "POSI;%.3f;%d;%.8f;%.8f;0;0" % (t, k + 1, la, lo))
    ev.sort(key=lambda e: e[0])
    with open(path, 'w', newline='') as out:
        out.write("\n".join(hdr))
        for _, text in ev:
            out.write("\n" + text)        # the logger writes "\nTYPE;..." (no newline at the end)

gsd('getsensordata-walk.txt')
