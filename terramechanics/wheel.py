"""The model's wheel is the one domain wheel (:class:`swtlab_base.domain.Wheel`): radius, width,
grousers; ``grouser_count`` and ``grouser_height_m`` only matter when the ``grousers`` effect
is on, and the model's stiffness is the ``wheel_flexibility`` effect's parameter."""

from swtlab_base.domain.wheel import Wheel

__all__ = ["Wheel"]
