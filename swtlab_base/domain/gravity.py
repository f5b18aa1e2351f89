"""Gravity constants, m/s^2: one standard gravity g0 and the planetary surface values."""

#: standard gravity g0, exact by definition (3rd CGPM 1901; ISO 80000-3:2019, item 3-9.1);
#: the gravity of every Earth test unless the run metadata gives its own
G0_MPS2 = 9.80665

#: mean lunar surface gravity (NASA GSFC Moon Fact Sheet, Williams 2024: 1.62 m/s^2)
MOON_GRAVITY_MPS2 = 1.62

#: mean Martian surface gravity at the equator (NASA GSFC Mars Fact Sheet, Williams 2024:
#: 3.71 m/s^2)
MARS_GRAVITY_MPS2 = 3.71
