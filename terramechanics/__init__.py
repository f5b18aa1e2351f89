"""Terramechanics model of the single-wheel test with switchable effects.

Classical rigid-wheel model (Bekker pressure-sinkage, Wong-Reece stress
distribution, Janosi-Hanamoto shear), vectorised over loads and slips, with the
effects of :data:`EFFECTS` switched on by name, each by one of its published laws
(:data:`LAWS`). See ``docs/model-file.md``.
"""

from terramechanics.conversions import (drucker_prager_to_mohr_coulomb,
                                        mohr_coulomb_to_drucker_prager)
from terramechanics.effects import (DEFAULT_LAWS, EFFECTS, LAWS, PUBLISHED_LAWS, Effect,
                                    law_class, make_effect, published_law)
from terramechanics.model import WheelModel
from terramechanics.model_file import (load_model, model_from_dict, model_to_dict, save_model,
                                       shipped_model)
from terramechanics.soil import LETE_SAND, LUNAR_NOMINAL, SOILS, WONG_DRY_SAND, SoilParams
from terramechanics.state import EARTH_GRAVITY_MPS2
from terramechanics.testbed_law import ModelLaw
from terramechanics.wheel import Wheel

__all__ = [
    "DEFAULT_LAWS", "EARTH_GRAVITY_MPS2", "EFFECTS", "Effect", "LAWS", "LETE_SAND",
    "LUNAR_NOMINAL", "ModelLaw", "PUBLISHED_LAWS", "SOILS", "SoilParams", "WONG_DRY_SAND",
    "Wheel", "WheelModel", "drucker_prager_to_mohr_coulomb", "law_class", "load_model",
    "make_effect", "model_from_dict", "model_to_dict", "mohr_coulomb_to_drucker_prager",
    "published_law", "save_model", "shipped_model",
]
