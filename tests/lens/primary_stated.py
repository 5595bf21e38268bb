"""Bundled lenses re-entered from their patents' own printed pages (issue 44), as the patents state them.

The tables were typed from the patents' scanned pages (a reading independent of the lens files',
done a second time for the tests), not from physcam's files or output.
"""

#: US 2,701,982 (P. Angenieux, 1955), claim 4's table (column 3; column 2 prints the same): radius,
#: the thickness or air space after it (e1 ... e13), nD and v of the glass after it (None: air).
US_2701982 = [
    (164.13, 10.99, 1.6751, 32.3), (559.20, 0.23, None, None), (100.12, 11.45, 1.6689, 46.7),
    (213.54, 0.23, None, None), (58.04, 22.95, 1.6913, 53.8), (2551.10, 2.58, 1.6751, 32.3),
    (32.39, 30.66, None, None), (-40.42, 2.74, 1.6992, 30.2), (192.98, 27.92, 1.6204, 60.2),
    (-55.53, 0.23, None, None), (192.98, 7.98, 1.6913, 53.8), (-225.30, 0.23, None, None),
    (175.09, 8.48, 1.6913, 53.8), (-203.55, None, None, None),
]
#: US 2,500,046 (W. Schade / Eastman Kodak, 1950), the table of column 3 (Fig. 2 prints the same); R3 is
#: flat (0 here, as physcam writes a flat), s1 49.3 holds the stop.
US_2500046 = [
    (70.97, 15.0, 1.523, 58.6), (-56.79, 4.5, 1.617, 38.5), (0.0, 49.3, None, None), (119.91, 3.8, 1.649, 33.8),
    (40.87, 0.9, None, None), (46.87, 7.5, 1.697, 56.1), (-282.05, None, None, None),
]
#: US 3,583,791 (I. Mori / Nippon Kogaku, 1971), Example I as columns 2 and 3 print it (claim 2, column 4,
#: prints the same but R10 = -188.11, which would make L5 a meniscus where the text says biconcave and
#: the focal length 53.1): the stop sits in d8.
US_3583791 = [
    (96.15, 7.00, 1.6425, 58.1), (53.85, 17.83, None, None), (117.48, 5.59, 1.58904, 53.2), (69.93, 52.45, None, None),
    (106.64, 15.73, 1.76684, 46.2), (-188.11, 4.90, None, None), (-192.31, 15.38, 1.76684, 46.2),
    (-140.91, 19.58, None, None), (-65.04, 16.22, 1.7552, 27.5), (188.11, 2.52, None, None), (-323.43, 7.00, 1.713, 53.9),
    (-65.39, 0.18, None, None), (-8741.25, 6.64, 1.6583, 57.3), (-117.55, None, None, None),
]
#: US 3,583,791, Example II as claim 3 (column 4) prints it (column 3 prints the same but R13 = 3,921.60, which
#: would make the focal length 95.79 and Bf 131.29): L5 (R9-R9') and L5' (R9'-R10) cemented; the stop sits in d8.
US_3583791_EX2_R13_COLUMN3 = 3921.60
US_3583791_EX2 = [
    (94.12, 3.14, 1.62041, 60.3), (52.16, 15.69, None, None), (117.65, 3.14, 1.62041, 60.3), (67.84, 52.94, None, None),
    (101.96, 14.90, 1.76684, 46.2), (-188.83, 4.71, None, None), (-190.20, 14.41, 1.76684, 46.2),
    (-140.79, 20.59, None, None), (-64.48, 1.96, 1.79504, 28.4), (147.06, 15.29, 1.79668, 45.3),
    (191.18, 2.88, None, None), (-323.53, 6.08, 1.6968, 55.6), (-66.47, 0.2, None, None),
    (-3921.60, 6.47, 1.6425, 58.1), (-99.63, None, None, None),
]
#: US 3,451,745 (T. Kazamaki, Y. Takahashi / Asahi Kogaku, 1969), the table of column 4 (claim 1 prints it
#: in units of F); the stop sits in d6.
US_3451745 = [
    (110.000, 10.00, 1.80416, 46.6), (588.748, 0.20, None, None), (51.600, 14.50, 1.79446, 45.4),
    (100.426, 3.50, None, None), (119.000, 3.00, 1.71736, 29.5), (32.792, 32.50, None, None),
    (-36.500, 2.00, 1.68893, 31.1), (131.500, 20.00, 1.77252, 49.6), (-56.806, 0.20, None, None),
    (-160.000, 8.50, 1.77252, 49.6), (-74.352, 0.20, None, None), (122.000, 9.50, 1.77252, 49.6),
    (2092.573, None, None, None),
]
#: US 3,841,736 (Y. Takahashi, S. Okudaira / Asahi Kogaku, 1974), Table I (claim 1 prints the same), but r14:
#: both print -52.41, and the patent's own F = 100, F_B = 198.7, F7 = 102.06 and F8 = -69.76 all need -62.41
#: (tests below); the stop sits in d12.
US_3841736_R14_PRINTED = -52.41
US_3841736 = [
    (196.25, 9.57, 1.80610, 40.8), (95.73, 47.09, None, None), (3033.14, 43.17, 1.53172, 48.9),
    (-342.39, 0.65, None, None), (130.31, 7.23, 1.69350, 53.3), (57.80, 18.81, None, None),
    (246.94, 7.45, 1.71300, 54.0), (72.22, 14.74, None, None), (235.07, 18.11, 1.74077, 27.8),
    (-357.57, 18.97, None, None), (272.12, 36.59, 1.60562, 43.7), (-86.37, 13.70, None, None),
    (312.47, 18.11, 1.51823, 59.0), (-62.41, 5.76, 1.83400, 37.2), (894.12, 8.43, None, None),
    (-1416.27, 16.64, 1.69350, 53.3), (-110.97, 0.49, None, None), (-887.30, 5.27, 1.80518, 25.4),
    (118.00, 10.71, None, None), (-1386.54, 16.31, 1.64850, 53.0), (-98.62, None, None, None),
]
#: US 3,841,736, the second embodiment (Fig. 3): Table III (claim 2 prints the same); r3 flat (0 here, as physcam
#: writes a flat); the stop sits in d12.
US_3841736_EX2 = [
    (229.52, 8.64, 1.64000, 60.2), (94.56, 47.57, None, None), (0.0, 39.89, 1.51633, 64.1),
    (-312.73, 1.62, None, None), (150.12, 9.62, 1.64000, 60.2), (56.47, 18.91, None, None),
    (167.82, 9.62, 1.51633, 64.1), (65.37, 16.22, None, None), (333.50, 9.62, 1.64000, 60.2),
    (-1093.72, 21.62, None, None), (181.10, 25.40, 1.62588, 35.7), (-95.77, 15.68, None, None),
    (424.27, 23.24, 1.51633, 64.1), (-58.17, 6.40, 1.83400, 37.2), (253.87, 8.11, None, None),
    (-1502.70, 14.59, 1.48749, 70.1), (-72.53, 0.54, None, None), (324.32, 5.78, 1.80518, 25.4),
    (121.74, 10.81, None, None), (1043.14, 18.92, 1.51633, 64.1), (-106.74, None, None, None),
]
#: What column 6 prints beside Table III: the focal lengths F7, F8 of lenses 7 and 8, |F1.2.3.4| = F/1.786 and
#: F1.2.3.4.5.6 = F/0.878; and Table IV's P (Petzval) column, headed "for the lens system of Table I" but Table
#: III's (Table II is Table I's), with its printed sum.
US_3841736_EX2_STATED = dict(f7=100.70, f8=-56.22, f1234=-55.99, f123456=113.90,
                             pt=(0.17, -0.41, 0.00, 0.11, 0.26, -0.69, 0.20, -0.52, 0.12, 0.04, 0.21, 0.40, 0.08,
                                 -0.20, -0.18, -0.02, 0.45, 0.14, -0.37, 0.03, 0.32), pt_sum=0.14)
#: US 3,506,336 (Y. Takahashi / Asahi Kogaku, 1970), Table 1 (claim 1 prints the same); the stop sits in t4.
US_3506336 = [
    (450.000, 7.00, 1.58913, 61.2), (80.137, 47.00, None, None), (-2300.000, 10.00, 1.76200, 40.3),
    (-292.234, 2.00, None, None), (95.700, 18.00, 1.77252, 49.6), (-707.468, 1.00, None, None),
    (80.000, 8.00, 1.53172, 48.9), (84.488, 18.00, None, None), (-91.500, 6.50, 1.74077, 27.7),
    (98.025, 8.00, None, None), (1000.000, 4.00, 1.83400, 37.2), (71.000, 19.00, 1.77252, 49.6),
    (-89.354, 0.50, None, None), (-600.000, 10.00, 1.77252, 49.6), (-110.648, None, None, None),
]

#: US 4,310,222 (K. Ikemori / Canon, 1982), the first embodiment: the table of columns 8 and 9 (R3 is
#: non-spherical, coefficients below); the stop sits in D15.
US_4310222 = [
    (44.344, 3.0, 1.6968, 55.5), (25.494, 10.63, None, None), (56.952, 6.14, 1.6031, 60.7), (58.976, 1.0, None, None),
    (32.455, 1.5, 1.6968, 55.5), (15.699, 5.45, None, None), (34.226, 1.5, 1.7725, 49.7), (16.356, 4.18, None, None),
    (202.88, 2.0, 1.6968, 55.5), (12.66, 12.71, 1.60342, 38.0), (-41.964, 2.187, None, None),
    (56.099, 8.88, 1.51742, 52.3), (-13.786, 0.738, None, None), (-12.664, 1.2, 1.7725, 49.7),
    (-26.477, 1.7, None, None), (140.256, 7.98, 1.69895, 30.1), (-14.608, 1.0, 1.62606, 39.1),
    (55.637, 0.846, None, None), (-55.153, 1.0, 1.84666, 23.9), (27.603, 4.24, 1.48749, 70.1),
    (-15.512, 0.15, None, None), (111.951, 3.41, 1.60311, 60.7), (-32.396, None, None, None),
]
#: The fourth embodiment: the table of column 13 (R3 non-spherical); the stop sits in D10.
US_4310222_EX4 = [
    (36.562, 2.5, 1.6968, 55.5), (18.877, 6.76, None, None), (36.009, 5.31, 1.60311, 60.7), (36.0, 0.16, None, None),
    (26.936, 1.5, 1.6968, 55.7), (10.237, 7.52, None, None), (40.279, 12.62, 1.60342, 38.0), (-15.661, 1.116, None, None),
    (-13.1, 1.0, 1.7725, 49.6), (-27.485, 1.7, None, None), (87.301, 5.967, 1.69895, 30.1),
    (-16.511, 1.0, 1.59551, 39.2), (123.783, 1.788, None, None), (-56.858, 1.0, 1.92286, 21.3),
    (27.983, 4.0, 1.48749, 70.1), (-15.574, 0.15, None, None), (1652.078, 2.65, 1.7725, 49.6), (-29.01, None, None, None),
]
#: The fifth embodiment: the table of column 15 (R3 non-spherical); the stop sits in D13. R6 is printed
#: 3.3649; the patent's own h column, Petzval term and f need 8.3649 (the file's; tests below).
US_4310222_R6_PRINTED = 3.3649
US_4310222_EX5 = [
    (49.0189, 2.3, 1.6968, 55.5), (15.0921, 4.48, None, None), (47.2056, 4.0, 1.60311, 60.7), (47.2056, 1.0, None, None),
    (21.34, 1.0, 1.6968, 55.5), (8.3649, 5.685, None, None), (514.905, 1.5, 1.6968, 55.5), (7.745, 9.46, 1.60342, 38.0),
    (-139.463, 1.3, None, None), (33.6069, 7.295, 1.60342, 38.0), (-16.1228, 1.6, None, None),
    (-10.9129, 1.0, 1.7725, 49.6), (-18.1377, 1.7, None, None), (131.723, 6.376, 1.59551, 39.2),
    (35.387, 0.927, None, None), (-489.874, 0.7, 1.92286, 21.3), (16.7027, 3.684, 1.48749, 70.1),
    (-11.9649, 0.15, None, None), (23.5946, 2.925, 1.7725, 49.6), (-31.1173, None, None, None),
]
#: The second embodiment: the table of column 10 (R3 non-spherical; R12-R13 a filter, radius 0 = the table's
#: infinity); the stop sits in D17. R16 is printed 12.614; its own Petzval term, h columns and the lens's shape
#: need -12.614 (the file's; the table here holds what the file must have, US_4310222_EX2_R16_PRINTED the print).
US_4310222_EX2_R16_PRINTED = 12.614
US_4310222_EX2 = [
    (38.794, 3.1, 1.72, 50.2), (24.997, 12.41, None, None), (58.28, 5.02, 1.6031, 60.7), (46.009, 0.15, None, None),
    (33.022, 1.7, 1.6968, 55.5), (17.647, 5.39, None, None), (32.787, 1.3, 1.7725, 49.7), (17.218, 6.32, None, None),
    (266.96, 1.5, 1.6968, 55.5), (13.984, 12.08, 1.60342, 38.0), (-43.016, 2.2, None, None),
    (0.0, 1.8, 1.51633, 64.1), (0.0, 0.8, None, None), (74.564, 7.84, 1.51118, 51.0), (-14.201, 0.94, None, None),
    (-12.614, 0.9, 1.7725, 49.7), (-26.958, 1.7, None, None), (129.909, 2.0, 1.64769, 33.8),
    (12.278, 6.9, 1.69895, 30.1), (50.377, 0.83, None, None), (-80.749, 0.8, 1.84666, 23.9),
    (28.151, 4.4, 1.48749, 70.1), (-15.466, 0.15, None, None), (493.467, 2.85, 1.7725, 49.7), (-33.952, None, None, None),
]
#: The third embodiment: the table of column 12 (R3 non-spherical; R12-R13 the filter again); the stop sits in D18.
US_4310222_EX3 = [
    (41.022, 3.1, 1.6968, 55.5), (25.486, 11.61, None, None), (59.586, 5.8, 1.60311, 60.7), (53.247, 0.15, None, None),
    (31.755, 1.7, 1.6968, 55.5), (16.408, 5.63, None, None), (32.689, 1.3, 1.7725, 49.7), (16.569, 5.98, None, None),
    (327.3, 1.5, 1.6968, 55.5), (13.739, 10.42, 1.60342, 38.0), (-62.67, 2.2, None, None),
    (0.0, 1.8, 1.51633, 64.1), (0.0, 0.8, None, None), (50.943, 6.24, 1.51118, 51.0),
    (-12.241, 1.0, 1.6968, 55.5), (-14.812, 1.14, None, None), (-13.815, 0.9, 1.7725, 49.7),
    (-26.056, 1.7, None, None), (122.96, 9.74, 1.69895, 30.1), (-17.987, 2.15, 1.59551, 39.2),
    (56.343, 0.68, None, None), (-160.37, 0.8, 1.92286, 21.3), (28.576, 4.77, 1.48749, 70.1),
    (-17.792, 0.15, None, None), (219.82, 2.75, 1.7725, 49.7), (-42.458, None, None, None),
]
#: The sixth embodiment: the table of columns 16 and 17 (R3 non-spherical); the stop sits in D14.
US_4310222_EX6 = [
    (47.3142, 2.3, 1.6968, 55.5), (14.9039, 4.613, None, None), (46.113, 4.0, 1.60311, 60.7), (46.113, 1.0, None, None),
    (21.4146, 1.0, 1.6968, 55.5), (8.4483, 5.667, None, None), (577.663, 1.5, 1.6968, 55.5), (7.603, 9.482, 1.60342, 38.0),
    (-220.61, 1.3, None, None), (30.088, 6.54, 1.60342, 38.0), (-13.4264, 1.0, 1.6968, 55.5),
    (-16.0569, 1.672, None, None), (-10.9266, 1.0, 1.7725, 49.6), (-18.0916, 1.7, None, None),
    (131.185, 5.98, 1.59551, 39.2), (35.313, 0.92, None, None), (-488.534, 0.7, 1.92286, 21.3),
    (16.7051, 3.605, 1.48749, 70.1), (-11.9702, 0.15, None, None), (23.5131, 2.961, 1.7725, 49.6),
    (-31.1174, None, None, None),
]
#: The seventh embodiment: the table of columns 19 and 20 (R3 non-spherical, on the plastic meniscus R3-R4,
#: N 1.493; R12-R13 a filter); no h columns. The stop: 0.30 f behind R15 (the patent's "surface R"), in D18.
US_4310222_EX7 = [
    (42.889, 3.1, 1.6968, 55.5), (26.161, 11.55, None, None), (61.567, 5.83, 1.493, 54.2), (57.577, 0.15, None, None),
    (30.956, 1.7, 1.6968, 55.5), (16.443, 5.75, None, None), (32.978, 1.3, 1.7725, 49.6), (16.486, 5.95, None, None),
    (357.247, 1.5, 1.6968, 55.5), (12.444, 10.4, 1.60342, 38.0), (-55.993, 2.53, None, None),
    (0.0, 1.8, 1.51633, 64.1), (0.0, 0.7, None, None), (49.441, 5.6, 1.51742, 52.3),
    (-12.228, 1.5, 1.6968, 55.5), (-14.588, 1.08, None, None), (-13.862, 0.9, 1.7725, 49.6),
    (-25.881, 1.7, None, None), (136.4, 9.65, 1.68893, 31.1), (-21.198, 1.9, 1.59551, 39.2),
    (54.226, 0.69, None, None), (-160.011, 0.8, 1.92286, 21.3), (28.566, 5.53, 1.48749, 70.1),
    (-17.829, 0.1, None, None), (277.71, 2.63, 1.804, 46.6), (-43.605, None, None, None),
]
#: The eighth embodiment: the table of column 21 (R3 non-spherical, on the plastic meniscus R3-R4); no h columns.
#: N7 is printed 1.6968 (v 30.1); the file has 1.69895 (US_4310222_EX8_N7_PRINTED the print; test below). The stop:
#: 0.19 f behind R10 (the patent's "surface R"), in D12.
US_4310222_EX8_N7_PRINTED = 1.6968
US_4310222_EX8 = [
    (35.43, 2.5, 1.6968, 55.5), (17.531, 6.8, None, None), (35.8, 5.3, 1.493, 54.2), (36.5, 0.15, None, None),
    (21.591, 1.5, 1.6968, 55.5), (10.2174, 6.0, None, None), (300.0, 8.0, 1.60342, 38.0), (-46.177, 1.5, None, None),
    (124.799, 7.0, 1.60342, 38.0), (-14.3706, 1.1, None, None), (-13.0615, 1.0, 1.6968, 55.5),
    (-36.637, 2.3, None, None), (67.788, 3.7, 1.69895, 30.1), (-129.82, 1.0, 1.66672, 48.3),
    (55.651, 1.2, None, None), (-51.303, 1.0, 1.92286, 21.3), (29.3603, 4.5, 1.48749, 70.1),
    (-15.9063, 0.15, None, None), (-340.986, 3.2, 1.7725, 49.6), (-23.448, None, None, None),
]
#: What the patent prints beside each of its tables: R3's non-spherical coefficients B, C, D, E (A = 0:
#: X = R(1 - (1 - H^2/R^2)^(1/2)) + A H^2 + B H^4 + ... + E H^10); the h (axial paraxial ray, incident height
#: 1) and h-bar (principal ray, f = 1) columns (the seventh and eighth print none); the third-order table's PT (Petzval) column and its total
#: (row 20 of the first is printed -0.6776); its lens groups' focal lengths (first and last surface, in units
#: of the stated f); and the stated f those are in.
US_4310222_COLUMNS = {
    "canon_wide_angle_us4310222_14mm_f2_8": dict(
        asphere=(9.660e-6, 2.605e-9, 1.106e-11, 2.260e-14),
        h=(1.000, 0.972, 1.088, 1.085, 1.096, 1.084, 1.275, 1.280, 1.559, 1.631, 2.213, 2.304, 2.423, 2.371,
           2.421, 2.427, 2.386, 2.373, 2.378, 2.401, 2.612, 2.610, 2.563),
        hbar=(-1.942, -1.764, -1.208, -0.958, -0.903, -0.837, -0.632, -0.588, -0.487, -0.457, -0.280, -0.223,
              -0.056, -0.034, -0.014, 0.035, 0.170, 0.187, 0.212, 0.230, 0.333, 0.337, 0.388),
        pt=(0.1322, -0.2300, 0.0943, -0.0910, 0.1806, -0.3735, 0.1818, -0.3804, 0.0289, -0.0387, 0.1280, 0.0867,
            0.3531, -0.4914, 0.2350, 0.0418, 0.0257, -0.0988, -0.1187, -0.6776, 0.3016, 0.0479, 0.1658),
        pt_total=0.1138, groups=((1, 8, -1.06), (9, 15, 2.67), (16, 23, 2.37)), f=14.2, bf=36.6),
    "canon_wide_angle_us4310222_14mm_f2_8_ex2": dict(
        asphere=(9.556e-6, 2.591e-9, -1.015e-11, 2.128e-14),
        h=(1.000, 0.967, 1.082, 1.076, 1.078, 1.067, 1.237, 1.239, 1.606, 1.653, 2.142, 2.219, 2.260, 2.288,
           2.387, 2.324, 2.363, 2.376, 2.371, 2.315, 2.330, 2.348, 2.563, 2.562, 2.542),
        hbar=(-2.087, -1.891, -1.217, -1.007, -0.999, -0.925, -0.718, -0.678, -0.521, -0.498, -0.326, -0.266,
              -0.233, -0.211, -0.062, -0.033, -0.018, 0.033, 0.068, 0.187, 0.213, 0.228, 0.337, 0.341, 0.382),
        pt=(0.1540, -0.2391, 0.0921, -0.1167, 0.1775, -0.3322, 0.1898, -0.3614, 0.0219, -0.0350, 0.1249, 0.0000,
            0.0000, 0.0647, 0.3401, -0.4933, 0.2308, 0.0432, 0.0212, -0.1166, -0.0810, -0.0663, 0.3023, 0.0126,
            0.1832),
        pt_total=0.1172, groups=((9, 17, 3.24), (18, 25, 2.24)), f=14.2, bf=36.3),
    "canon_wide_angle_us4310222_14mm_f2_8_ex3": dict(
        asphere=(9.452e-6, 2.539e-9, -1.049e-11, 2.118e-14),
        h=(1.000, 0.969, 1.079, 1.074, 1.076, 1.063, 1.245, 1.247, 1.612, 1.662, 2.110, 2.217, 2.274, 2.313,
           2.418, 2.454, 2.393, 2.434, 2.448, 2.415, 2.389, 2.393, 2.401, 2.581, 2.578, 2.541),
        hbar=(-2.036, -1.845, -1.216, -0.975, -0.967, -0.890, -0.672, -0.632, -0.481, -0.457, -0.307, -0.249,
              -0.218, -0.198, -0.082, -0.066, -0.032, -0.017, 0.032, 0.195, 0.232, 0.252, 0.265, 0.379, 0.382,
              0.419),
        pt=(0.1429, -0.2301, 0.0901, -0.1009, 0.1847, -0.3574, 0.1904, -0.3757, 0.0179, -0.0356, 0.0857, 0.0000,
            0.0000, 0.0948, -0.0844, 0.3960, -0.4506, 0.2389, 0.0477, 0.0303, -0.0946, -0.0427, -0.0760, 0.2631,
            0.0283, 0.1466),
        pt_total=0.1094, groups=((1, 8, -1.15), (9, 18, 3.19), (19, 26, 2.30)), f=14.2, bf=36.3),
    "canon_wide_angle_us4310222_17mm_f2_8": dict(
        asphere=(2.530e-5, 1.505e-8, -2.012e-11, 2.102e-13),
        h=(1.000, 0.972, 1.086, 1.081, 1.084, 1.074, 1.539, 1.844, 1.808, 1.849, 1.887, 1.913, 1.910, 1.918,
           1.936, 2.113, 2.113, 2.110),
        hbar=(-1.133, -1.016, -0.734, -0.555, -0.548, -0.496, -0.306, -0.072, -0.036, -0.019, 0.034, 0.142,
              0.160, 0.215, 0.233, 0.334, 0.338, 0.379),
        pt=(0.1948, -0.3773, 0.1812, -0.1812, 0.2644, -0.6958, 0.1620, 0.4168, -0.5770, 0.2750, 0.0817, 0.0400,
            -0.0523, -0.1464, -0.0943, 0.3650, 0.0045, 0.2605),
        pt_total=0.1218, groups=((1, 6, -0.93), (7, 10, 2.46), (11, 18, 1.54)), f=17.34, bf=36.61),
    "canon_wide_angle_us4310222_5_5mm_f1_6": dict(
        asphere=(1.111e-4, -1.823e-7, -6.583e-11, 6.906e-12),
        h=(1.000, 0.981, 1.120, 1.162, 1.193, 1.189, 1.710, 1.789, 2.444, 2.574, 2.820, 2.738, 2.819, 2.857,
           2.894, 2.948, 2.971, 3.321, 3.322, 3.152),
        hbar=(-2.561, -2.266, -1.761, -1.423, -1.305, -1.211, -0.876, -0.823, -0.526, -0.458, -0.182, -0.073,
              -0.038, 0.070, 0.325, 0.389, 0.414, 0.614, 0.622, 0.680),
        pt=(0.0462, -0.1502, 0.0439, -0.0439, 0.1062, -0.2709, 0.0044, -0.0244, 0.0148, 0.0618, 0.1288, -0.2204,
            0.1326, 0.0156, -0.0582, -0.0054, -0.0503, 0.1511, 0.1019, 0.0773),
        pt_total=0.0611, groups=((1, 6, -1.976), (7, 13, 7.22), (14, 20, 2.735)), f=5.52, bf=17.4),
    "canon_wide_angle_us4310222_5_5mm_f1_6_ex6": dict(
        asphere=(1.099e-4, -1.747e-7, -1.411e-11, 6.880e-12),
        h=(1.000, 0.980, 1.123, 1.164, 1.196, 1.192, 1.707, 1.786, 2.442, 2.577, 2.791, 2.834, 2.748, 2.829,
           2.867, 2.903, 2.957, 2.980, 3.323, 3.324, 3.152),
        hbar=(-2.582, -2.285, -1.767, -1.429, -1.312, -1.218, -0.883, -0.830, -0.535, -0.468, -0.221, -0.186,
              -0.073, -0.038, 0.070, 0.308, 0.371, 0.396, 0.589, 0.597, 0.658),
        pt=(0.0479, -0.1520, 0.0450, -0.0450, 0.1058, -0.2683, 0.0039, -0.0249, 0.0094, 0.0690, -0.0141, 0.1411,
            -0.2201, 0.1329, 0.0157, -0.0583, -0.0054, -0.0502, 0.1511, 0.1023, 0.0773),
        pt_total=0.0630, groups=((1, 6, -1.991), (7, 14, 7.343), (15, 21, 2.738)), f=5.52, bf=17.4),
    "canon_wide_angle_us4310222_14mm_f2_8_ex7": dict(
        asphere=(1.07336e-5, 5.38038e-9, -1.98246e-11, 3.65339e-14),
        pt=(0.1368, -0.2243, 0.0766, -0.0819, 0.1895, -0.3568, 0.1888, -0.3777, 0.0164, -0.0394, 0.0960, 0.0000,
            0.0000, 0.0985, -0.0814, 0.4022, -0.4492, 0.2406, 0.0427, 0.0233, -0.0983, -0.0428, -0.0761, 0.2626,
            0.0229, 0.1460),
        pt_total=0.1151, groups=(), f=14.2, bf=36.1),
    "canon_wide_angle_us4310222_17mm_f2_8_ex8": dict(
        asphere=(2.51989e-5, 2.25528e-8, -2.51574e-11, 3.21205e-13),
        pt=(0.2009, -0.4061, 0.1599, -0.1568, 0.3297, -0.6969, 0.0217, 0.1413, 0.0522, 0.4540, -0.5451, 0.1943,
            0.1052, 0.0015, -0.1246, -0.1622, -0.0898, 0.3572, -0.0221, 0.3223),
        pt_total=0.1367, groups=(), f=17.3, bf=36.2),
}

#: slug -> (the patent's table, what the patent states: focal length, f-number, back focus from the last
#: vertex (None: the patent states none) and the tolerance its printed digits allow).
PRIMARY = {
    "angenieux_us2701982_100mm_f1": (US_2701982, dict(efl=100.0, fno=1.0, bf=56.0, bf_tol=0.5)),
    # Schade: "a focal length of 100 mm." (column 3), Fig. 3's aberrations plotted to "f:2.0", BF = 56.5
    "kodak_petzval_us2500046_100mm_f2": (US_2500046, dict(efl=100.0, fno=2.0, bf=56.5, bf_tol=0.05)),
    # Mori: "relative aperture is F/2.8, the angle of field is 75 deg, and the focal length f=100", Bf=131.19.
    # The printed example is 0.17 % short of f = 100 throughout (EFL 99.83), so its back focus is 0.27 mm
    # short too (0.21 %): the tolerance is the 0.5 % of the issue, not the printed digits
    # Kazamaki and Takahashi: "a focal length of 100 mm. and a relative aperture of 1:1.2"; no back focus
    "asahi_us3451745_100mm_f1_2": (US_3451745, dict(efl=100.0, fno=1.2, bf=None)),
    # Takahashi and Okudaira: F 100, "aperture ratio of 1:3.5" (column 6), F_B = 1.987F = 198.7
    "asahi_wide_angle_us3841736_100mm_f3_5": (US_3841736, dict(efl=100.0, fno=3.5, bf=198.7, bf_tol=0.05)),
    # the same, Table III: "likewise based on a lens system of focal length F = 100", Fig. 4's aberrations to
    # "1:3.5", F_B = 1.997F = 199.7
    "asahi_wide_angle_us3841736_100mm_f3_5_ex2": (US_3841736_EX2, dict(efl=100.0, fno=3.5, bf=199.7, bf_tol=0.05)),
    # Takahashi: "resultant focal length F=100" (column 2), Fig. 2's aberrations to "1:2.0"; no back focus
    "asahi_wide_angle_us3506336_100mm_f2": (US_3506336, dict(efl=100.0, fno=2.0, bf=None)),
    "nikon_retrofocus_us3583791_100mm_f2_8": (US_3583791, dict(efl=100.0, fno=2.8, bf=131.19, bf_tol=0.005 * 131.19)),
    # Mori, Example II: "the relative aperture is F/2.8, angle of field is 78 deg, and the focal length is f=100", Bf=137.24
    "nikon_retrofocus_us3583791_100mm_f2_8_ex2": (US_3583791_EX2, dict(efl=100.0, fno=2.8, bf=137.24, bf_tol=0.005)),
    # Ikemori: "f (focal distance) = 14.2; F No. = 1:2.8, bf (back focal distance) = 36.6, Angle of field = 114 deg".
    # The stated 14.2 is nominal: the patent's own h column gives f = bf / 2.563 = 14.280 (test below), which the
    # lens has (+0.56 %), so the EFL's tolerance is 0.6 % here and the design's f is checked at 0.1 % below
    "canon_wide_angle_us4310222_14mm_f2_8": (US_4310222, dict(efl=14.2, efl_rel=6e-3, fno=2.8, bf=36.6, bf_tol=0.05)),
    # the same, second embodiment (the first's f, F No. and field): "f = 14.2, bf = 36.3, F No. = 1:2.8, Angle of
    # field = 114 deg"; like the first, its h column ends at bf/f = 36.3/2.542, f = 14.280, +0.56 % from the nominal 14.2
    "canon_wide_angle_us4310222_14mm_f2_8_ex2": (US_4310222_EX2, dict(efl=14.2, efl_rel=6e-3, fno=2.8, bf=36.3, bf_tol=0.005)),
    # the third embodiment, the same stated values as the second; its h column ends at 36.3/2.541: f = 14.286
    "canon_wide_angle_us4310222_14mm_f2_8_ex3": (US_4310222_EX3, dict(efl=14.2, efl_rel=6e-3, fno=2.8, bf=36.3, bf_tol=0.005)),
    # the same, fourth embodiment: "f = 17.34, bf = 36.61, F No. = 1:2.8, Angle of field = 104 deg"
    "canon_wide_angle_us4310222_17mm_f2_8": (US_4310222_EX4, dict(efl=17.34, fno=2.8, bf=36.61, bf_tol=0.005)),
    # the same, fifth embodiment: "f = 5.52 ... bf = 17.2, F No. = 1:1.6, Angle of field = 99.8 deg". The printed
    # bf 17.2 is not this table's: its own h column ends at bf/f = 3.152, i.e. 17.40 (test below), as the
    # sixth embodiment's bf = 17.4 reads; the back focus is checked against 17.4
    "canon_wide_angle_us4310222_5_5mm_f1_6": (US_4310222_EX5, dict(efl=5.52, fno=1.6, bf=17.4, bf_tol=0.005)),
    # the same, sixth embodiment: "f = 5.52, bf = 17.4, F No. = 1:1.6, Angle of field = 99.8 deg"
    "canon_wide_angle_us4310222_5_5mm_f1_6_ex6": (US_4310222_EX6, dict(efl=5.52, fno=1.6, bf=17.4, bf_tol=0.005)),
    # the seventh embodiment: "f = 14.2; F No. = 1:2.8; bf = 36.1; Angle of field = 113.4 deg". No h column here, but its
    # Petzval column is computed with the table's f, 14.290 (+0.63 %; test below), the nominal 14.2 of the first three
    "canon_wide_angle_us4310222_14mm_f2_8_ex7": (US_4310222_EX7, dict(efl=14.2, efl_rel=7e-3, fno=2.8, bf=36.1, bf_tol=0.005)),
    # the eighth embodiment: "f = 17.3; F No. = 1:2.8; bf = 36.2; Angle of field = 102.7 deg"
    "canon_wide_angle_us4310222_17mm_f2_8_ex8": (US_4310222_EX8, dict(efl=17.3, fno=2.8, bf=36.2, bf_tol=0.05)),
}
