"""Radio layer: transponder channels, Doppler tuning logic, and radio backends (Hamlib rigctld)."""
