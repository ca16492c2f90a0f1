"""Output targets: what kind of armature a rig becomes, and which one a body plan can fill.

Each target names the target to fall back to when a skeleton's body plan cannot fill it; ``plain`` (the method's
bones as they are) fills every plan, so every chain of fallbacks ends there.
"""
from dataclasses import dataclass


@dataclass(frozen=True)
class Target:
    """An output target: ``name`` (the CLI's ``--target`` value), a ``label`` and ``description`` for the panel, the
    body plan kinds it can fill (None: every plan), the target it falls back to otherwise, and ``needs``: {plan kind:
    a part (a key of ``BodyPlan.parts``) that a plan of that kind must have to fill it}."""

    name: str
    label: str
    description: str
    plans: tuple = None
    fallback: str = None
    needs: dict = None

    def unfit(self, plan):
        """Why ``plan`` (a ``core.bodyplan.BodyPlan``, or None when not recognised) cannot fill this target, or None
        when it can."""
        if self.plans is None:
            return None
        kind = "unknown" if plan is None else plan.kind
        if kind not in self.plans:
            return f"the {self.name} target needs a {' or '.join(self.plans)} body plan, and this one is {kind}"
        part = (self.needs or {}).get(kind)
        if part is not None and not plan.parts.get(part):
            return f"the {self.name} target needs a {kind} with {part}, and this one has none ({plan.reason})"
        return None


TARGETS = {target.name: target for target in (
    Target("plain", "Plain", "The method's bones as they are, named by part (trunk, limbs, sides)"),
    Target("game", "Game", "A deform-only skeleton for game engines and mocap: a root bone on the ground, Mixamo "
                           "names on humanoids, at most 4 weights per vertex",
           plans=("humanoid", "quadruped", "bird", "fish"), fallback="plain"),
    Target("rigify", "Rigify", "Rigify's control rig (IK/FK, editable metarig) from its metarig fitted to the mesh",
           plans=("humanoid", "quadruped", "bird"), fallback="game", needs={"bird": "legs"}),
)}


class TargetFailed(ValueError):
    """A target's builder could not make this skeleton's armature (Rigify refused the metarig fitted to it): the
    target it falls back to is built instead."""


def _check_fallbacks(targets):
    """ValueError unless every target that does not fill every plan falls back, without a cycle, to one that does."""
    for target in targets.values():
        seen = [target.name]
        while target.plans is not None:
            if target.fallback not in targets or target.fallback in seen:
                raise ValueError(f"target {seen[0]!r} falls back to {target.fallback!r} after {seen}: fallbacks "
                                 f"must end in a target that fills every plan")
            target = targets[target.fallback]
            seen.append(target.name)


_check_fallbacks(TARGETS)


def check_target(name):
    """The :class:`Target` called ``name``; ValueError naming the targets there are otherwise."""
    if name not in TARGETS:
        raise ValueError(f"unknown target {name!r}; targets are {', '.join(TARGETS)}")
    return TARGETS[name]


def choose_target(name, plan):
    """(the target to build for a skeleton with body plan ``plan`` when ``name`` is asked for, a warning or None):
    ``name`` itself when the plan fills it, else the first target down its fallbacks that the plan fills, and a
    warning saying why."""
    target = check_target(name)
    reasons = []
    while (reason := target.unfit(plan)) is not None:
        reasons.append(reason)
        target = TARGETS[target.fallback]
    if not reasons:
        return target, None
    return target, f"{'; '.join(reasons)}: built the {target.name} target instead"
