"""Test data, the third referee: a modal test campaign read in (UFF files through pyuff, modes
identified from FRFs with sdypy-EMA), its nodes placed on the machine, the models' modes
correlated with it (MAC and frequency), and the scene keys nobody knows from a drawing
identified from it (README.md)."""
