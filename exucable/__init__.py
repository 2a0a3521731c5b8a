"""exucable: cable pulling tension through 3D conduits on the Exudyn multibody engine.

After Yang, Hong, Ren & Zhao, "Cable installation simulation by using a multibody
dynamic model", Multibody Syst Dyn 30 (2013) 433-447. SI units throughout.
"""

__version__ = "0.1.0"
