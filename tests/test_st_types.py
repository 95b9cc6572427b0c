"""verifier/st/types.py: FbType.param's index follows the groups the check fills in."""
from verifier.st import types as T


def test_fb_param_sees_groups_filled_in_after_a_lookup():
    # the collection creates a user FB's type empty, then sets its groups with
    # object.__setattr__ (check.py); a lookup made in between must not hide them
    fb = T.FbType("FB_Motor", standard=False)
    assert fb.param("i_bRun") is None
    object.__setattr__(fb, "inputs", (("i_bRun", T.BOOL),))
    object.__setattr__(fb, "outputs", (("o_bDone", T.BOOL), ("I_BRUN", T.INT)))
    assert fb.param("I_BRUN") == ("input", T.BOOL)  # the first group holding the name wins
    assert fb.param("o_bdone") == ("output", T.BOOL)
    object.__setattr__(fb, "inputs", ())
    assert fb.param("i_bRun") == ("output", T.INT)
    assert fb.param("x") is None
