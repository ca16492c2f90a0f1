"""Method discovery (error isolation, re-discovery, order) and the rig_mesh entry point."""
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import rigger
from rigger import api
from rigger.core.params import Param
from rigger.core.registry import RigMethod, discover
from rigger.core.skeleton import Skeleton
from rigger.methods._template import TemplateMethod

BOX_VERTICES = [(x, y, z) for x in (0, 1) for y in (0, 4) for z in (0, 1)]
BOX_TRIANGLES = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
                 (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]


def stick_method(name, class_name="Stick"):
    """Source of a one-bone method: a stick of ``length`` up from the centroid."""
    return f"""
        from rigger.core.params import Param
        from rigger.core.registry import RigMethod
        from rigger.core.skeleton import Skeleton

        class {class_name}(RigMethod):
            name = "{name}"
            params = (Param("length", "float", 1.0, min=0.1),)

            def rig(self, mesh, length):
                head = mesh.centroid
                return Skeleton(["stick"], [head], [head + (0, 0, length)], [-1], timings={{"up": 0.5}})
        """


def write(folder, filename, source):
    (folder / filename).write_text(textwrap.dedent(source))


@pytest.fixture
def scratch_registry(monkeypatch):
    """Let a test point rig_mesh at another methods folder; the previous registry comes back afterwards."""
    monkeypatch.setattr(api, "_registry", None)


# --- discovery ------------------------------------------------------------------------------------------------------

def test_discovery_collects_good_methods_and_records_broken_modules(tmp_path):
    write(tmp_path, "stick.py", stick_method("stick"))
    write(tmp_path, "broken_syntax.py", "def rig(:\n    pass\n")
    write(tmp_path, "broken_import.py", "import numpy\nimport rigger_no_such_module\n")
    write(tmp_path, "broken_runtime.py", "x = 1\nraise RuntimeError('boom')\n")
    write(tmp_path, "exits.py", "import sys\nsys.exit(3)\n")
    write(tmp_path, "helpers.py", "SCALE = 2\n")
    write(tmp_path, "_private.py", stick_method("private"))
    write(tmp_path, "notes.txt", "not python")
    registry = discover(tmp_path)
    assert list(registry.methods) == ["stick"]
    assert issubclass(registry.methods["stick"], RigMethod)
    assert set(registry.failures) == {"broken_syntax.py", "broken_import.py", "broken_runtime.py", "exits.py"}
    assert registry.failures["broken_syntax.py"].startswith("SyntaxError:")
    assert "(line 1)" in registry.failures["broken_syntax.py"]
    assert registry.failures["broken_import.py"] == \
        "ModuleNotFoundError: No module named 'rigger_no_such_module' (line 2)"
    assert registry.failures["broken_runtime.py"] == "RuntimeError: boom (line 2)"
    assert registry.failures["exits.py"].startswith("SystemExit: 3")


def test_methods_are_sorted_by_name_not_by_file(tmp_path):
    write(tmp_path, "a_file.py", stick_method("omega"))
    write(tmp_path, "m_file.py", stick_method("beta", "B") + stick_method("alpha", "A"))
    write(tmp_path, "z_file.py", stick_method("gamma"))
    assert list(discover(tmp_path).methods) == ["alpha", "beta", "gamma", "omega"]


def test_invalid_methods_are_recorded_and_skipped_without_losing_valid_neighbours(tmp_path):
    write(tmp_path, "a_first.py", stick_method("twin"))
    write(tmp_path, "b_mixed.py", stick_method("fine") + """
        class Nameless(RigMethod):
            def rig(self, mesh):
                pass

        class BadParams(RigMethod):
            name = "bad_params"
            params = ("length",)
            def rig(self, mesh):
                pass

        class Reserved(RigMethod):
            name = "reserved"
            params = (Param("method", "int", 1),)
            def rig(self, mesh, method):
                pass

        class NoRig(RigMethod):
            name = "no_rig"
        """)
    write(tmp_path, "c_second.py", stick_method("twin", "Twin"))
    registry = discover(tmp_path)
    assert list(registry.methods) == ["fine", "twin"]
    assert registry.methods["twin"].__name__ == "Stick"
    assert registry.failures == {
        "b_mixed.py:Nameless": "method name must be a Python identifier, got ''",
        "b_mixed.py:BadParams": "method 'bad_params': params must be a tuple of Param",
        "b_mixed.py:Reserved": "method 'reserved': parameter name 'method' is reserved",
        "b_mixed.py:NoRig": "method 'no_rig' does not define rig(mesh, **params)",
        "c_second.py:Twin": "duplicate method name 'twin', already defined in a_first.py:Stick",
    }


def test_a_bad_param_declaration_fails_its_module(tmp_path):
    write(tmp_path, "bad_default.py", """
        from rigger.core.params import Param
        LENGTH = Param("length", "float", -1.0, min=0.0)
        """)
    assert discover(tmp_path).failures == {
        "bad_default.py": "ValueError: parameter 'length': -1.0 is below the minimum 0.0 (line 3)"}


def test_methods_imported_from_another_module_are_not_collected_again(tmp_path):
    write(tmp_path, "reexport.py", "from rigger.methods._template import TemplateMethod\n")
    registry = discover(tmp_path)
    assert dict(registry.methods) == {} and dict(registry.failures) == {}


def test_rediscovery_sees_added_edited_and_removed_files(tmp_path, monkeypatch):
    monkeypatch.setattr(sys, "dont_write_bytecode", False)  # as inside Blender, where .pyc files get written
    write(tmp_path, "first.py", stick_method("first"))
    assert list(discover(tmp_path).methods) == ["first"]

    write(tmp_path, "second.py", stick_method("second"))
    assert list(discover(tmp_path).methods) == ["first", "second"]

    # Same size, same second: a .pyc keyed on modification time would serve the old name.
    write(tmp_path, "first.py", stick_method("fixed"))
    assert list(discover(tmp_path).methods) == ["fixed", "second"]

    (tmp_path / "second.py").unlink()
    write(tmp_path, "first.py", "raise ImportError('now broken')\n")
    registry = discover(tmp_path)
    assert dict(registry.methods) == {}
    assert registry.failures == {"first.py": "ImportError: now broken (line 1)"}

    write(tmp_path, "first.py", stick_method("first"))
    registry = discover(tmp_path)
    assert list(registry.methods) == ["first"] and dict(registry.failures) == {}


def test_shipped_methods_all_load_and_the_template_is_skipped():
    registry = discover()
    assert dict(registry.failures) == {}
    assert "template" not in registry.methods
    assert list(registry.methods) == sorted(registry.methods)


def test_lookup_of_an_unknown_name_lists_available_methods_and_failures(tmp_path):
    write(tmp_path, "stick.py", stick_method("stick"))
    write(tmp_path, "broken.py", "import rigger_no_such_module\n")
    with pytest.raises(ValueError) as error:
        discover(tmp_path).lookup("stik")
    assert str(error.value) == ("unknown method 'stik'; available: stick; failed to load: "
                                "broken.py: ModuleNotFoundError: No module named 'rigger_no_such_module' (line 1)")


# --- rig_mesh -------------------------------------------------------------------------------------------------------

def test_rig_mesh_runs_a_method_discovered_from_a_folder(tmp_path, scratch_registry):
    write(tmp_path, "stick.py", stick_method("stick"))
    assert list(api.method_registry(folder=tmp_path).methods) == ["stick"]
    skeleton = rigger.rig_mesh(BOX_VERTICES, BOX_TRIANGLES, method="stick", length="0.5")
    assert isinstance(skeleton, rigger.Skeleton)
    np.testing.assert_allclose(skeleton.heads, [(0.5, 2, 0.5)])
    np.testing.assert_allclose(skeleton.tails, [(0.5, 2, 1.0)])
    assert skeleton.params == {"length": 0.5}
    timings = skeleton.timings
    assert timings["up"] == 0.5 and 0 < timings["total"] < 10


def test_rig_mesh_errors_name_what_is_wrong(tmp_path, scratch_registry):
    write(tmp_path, "stick.py", stick_method("stick"))
    write(tmp_path, "broken.py", "import rigger_no_such_module\n")
    api.method_registry(folder=tmp_path)
    with pytest.raises(ValueError, match=r"unknown method 'silhouette'; available: stick; failed to load: broken.py"):
        rigger.rig_mesh(BOX_VERTICES, BOX_TRIANGLES)
    with pytest.raises(ValueError, match=r"unknown parameter lenght; valid: length"):
        rigger.rig_mesh(BOX_VERTICES, BOX_TRIANGLES, method="stick", lenght=2)
    with pytest.raises(ValueError, match=r"'length': 0.0 is below the minimum 0.1"):
        rigger.rig_mesh(BOX_VERTICES, BOX_TRIANGLES, method="stick", length=0)
    with pytest.raises(ValueError, match=r"reference vertex 8 but the mesh has only 8 vertices"):
        rigger.rig_mesh(BOX_VERTICES, [(0, 1, 8)], method="stick")
    with pytest.raises(ValueError, match=r"method must be a method name, a RigMethod subclass or an instance"):
        rigger.rig_mesh(BOX_VERTICES, BOX_TRIANGLES, method=None)


def test_rig_mesh_accepts_a_method_class_and_checks_it():
    class Wrong(RigMethod):
        name = "wrong"

        def rig(self, mesh):
            return [("bone", (0, 0, 0), (0, 0, 1))]

    with pytest.raises(TypeError, match="method 'wrong' returned list, not a Skeleton"):
        rigger.rig_mesh(BOX_VERTICES, BOX_TRIANGLES, method=Wrong)

    class Shadowing(Wrong):
        params = (Param("vertices", "int", 1),)

    with pytest.raises(ValueError, match="parameter name 'vertices' is reserved"):
        rigger.rig_mesh(BOX_VERTICES, BOX_TRIANGLES, method=Shadowing)


def test_the_template_method_rigs_a_chain_along_the_main_axis():
    skeleton = rigger.rig_mesh(BOX_VERTICES, BOX_TRIANGLES, method=TemplateMethod, bones="4")
    assert skeleton.names == ("chain.000", "chain.001", "chain.002", "chain.003")
    assert list(skeleton.parents) == [-1, 0, 1, 2]
    np.testing.assert_allclose(skeleton.heads[1:], skeleton.tails[:-1])
    (axis_line,) = skeleton.stages["principal_axis"].lines
    np.testing.assert_allclose(np.sort(axis_line[:, 1]), [0, 4], atol=1e-12)
    np.testing.assert_allclose(axis_line[:, [0, 2]], 0.5, atol=1e-12)
    ends = sorted([skeleton.heads[0][1], skeleton.tails[-1][1]])
    np.testing.assert_allclose(ends, [0, 4])
    np.testing.assert_allclose(skeleton.heads[:, [0, 2]], 0.5)
    assert set(skeleton.timings) == {"axis", "chain", "body_plan", "total"}  # rig_mesh adds the last two
    along_z = rigger.rig_mesh(BOX_VERTICES, BOX_TRIANGLES, method=TemplateMethod, axis="z")
    np.testing.assert_allclose(along_z.heads[0], [0.5, 2, 0])
    assert len(along_z) == 3


def test_the_template_draw_hook_uses_only_layout_and_props():
    class Layout:
        def label(self, text):
            self.text = text

    class Props:
        bones, axis = 5, "X"

    layout = Layout()
    TemplateMethod().draw(layout, Props())
    assert layout.text == "5 bones along X"
    assert RigMethod().draw(layout, Props()) is None


def test_import_rigger_is_cheap_and_exports_lazily():
    probe = ("import sys, rigger; heavy = [m for m in ('numpy', 'bpy', 'rigger.api') if m in sys.modules]; "
             "print(heavy); print(rigger.rig_mesh.__module__, rigger.Skeleton.__module__)")
    result = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    assert result.stdout.split("\n")[:2] == ["[]", "rigger.api rigger.core.skeleton"]
    assert rigger.Skeleton is Skeleton
    with pytest.raises(AttributeError, match="has no attribute 'rig_meshes'"):
        rigger.rig_meshes


# --- methods as packages, tuning tables, typed stages ---------------------------------------------------------------

def write_package(folder, name, modules):
    """A method package ``folder/name`` with the given {module file: source}."""
    (folder / name).mkdir(exist_ok=True)
    for filename, source in modules.items():
        write(folder / name, filename, source)


def package_method(method_name, height_source):
    """A package method whose bone height comes from its ``height`` module."""
    return {"__init__.py": f"""
                from rigger.core.registry import RigMethod
                from rigger.core.skeleton import Skeleton

                from .height import HEIGHT

                class Up(RigMethod):
                    name = "{method_name}"

                    def rig(self, mesh):
                        head = mesh.centroid
                        return Skeleton(["up"], [head], [head + (0, 0, HEIGHT)], [-1])
                """,
            "height.py": height_source}


def test_a_method_can_be_a_package_and_its_modules_reload_with_it(tmp_path, monkeypatch):
    monkeypatch.setattr(sys, "dont_write_bytecode", False)  # as inside Blender, where .pyc files get written
    write_package(tmp_path, "up", package_method("up", "HEIGHT = 1.0\n"))
    write(tmp_path, "stick.py", stick_method("stick"))
    registry = discover(tmp_path)
    assert list(registry.methods) == ["stick", "up"] and dict(registry.failures) == {}
    assert rigger.rig_mesh(BOX_VERTICES, BOX_TRIANGLES, method=registry.methods["up"]).tails[0, 2] == 1.5

    # An edit to a module of the package, same size, same second: seen on the next discovery.
    write(tmp_path / "up", "height.py", "HEIGHT = 2.0\n")
    registry = discover(tmp_path)
    assert rigger.rig_mesh(BOX_VERTICES, BOX_TRIANGLES, method=registry.methods["up"]).tails[0, 2] == 2.5


def test_a_broken_module_of_a_package_fails_that_method_naming_the_file_and_line(tmp_path):
    write_package(tmp_path, "up", package_method("up", "HEIGHT = 1.0\nraise RuntimeError('no height')\n"))
    write_package(tmp_path, "typo", package_method("typo", "HEIGHT = (\n"))
    write(tmp_path, "stick.py", stick_method("stick"))
    (tmp_path / "notes").mkdir()  # a folder without __init__.py is no method
    registry = discover(tmp_path)
    assert list(registry.methods) == ["stick"]
    assert registry.failures["up/"] == "RuntimeError: no height (height.py, line 2)"
    assert registry.failures["typo/"].startswith("SyntaxError:") and "height.py" in registry.failures["typo/"]
    assert set(registry.failures) == {"up/", "typo/"}


def test_the_shipped_silhouette_method_is_a_package_with_a_tuning_table():
    method = discover().methods["silhouette"]
    assert method.__module__.endswith("methods.silhouette")
    rows = method.tuning_type.rows()
    assert len(rows) >= 40 and all(why for _, _, why, _ in rows)  # every tuned number says why
    owners = {owner.__module__.rsplit(".", 1)[-1] for _, _, _, owner in rows}
    assert owners == {"tuning", "joints", "mirror"}


def test_tuning_is_changed_by_name_and_checked():
    silhouette = discover().methods["silhouette"]
    default = rigger.rig_mesh(BOX_VERTICES, BOX_TRIANGLES)
    same = rigger.rig_mesh(BOX_VERTICES, BOX_TRIANGLES, method=silhouette(tuning={"speck": 0.25}))
    np.testing.assert_array_equal(same.heads, default.heads)
    table = silhouette.tuning_type().changed(longest_bone=1, pair_prune=np.float64(0.6), path_candidates=np.int64(8))
    assert (table.longest_bone, table.pair_prune, table.path_candidates) == (1.0, 0.6, 8)
    assert type(table.longest_bone) is float and type(table.path_candidates) is int
    with pytest.raises(ValueError, match="unknown tuning value pair_prun of Tuning; valid: "):
        silhouette(tuning={"pair_prun": 0.6})
    with pytest.raises(ValueError, match="tuning value path_candidates must be a int like its default 32"):
        silhouette.tuning_type().changed(path_candidates=2.5)
    with pytest.raises(ValueError, match="must be a Tuning or a dict of its values"):
        silhouette(tuning=[("speck", 1.0)])
    with pytest.raises(ValueError, match="has no tuning to change"):
        RigMethod(tuning={"speck": 1.0})


def test_a_method_instance_is_run_as_it_is_and_checked():
    class Nameless(RigMethod):
        def rig(self, mesh):
            pass

    with pytest.raises(ValueError, match="method name must be a Python identifier"):
        rigger.rig_mesh(BOX_VERTICES, BOX_TRIANGLES, method=Nameless())
    skeleton = rigger.rig_mesh(BOX_VERTICES, BOX_TRIANGLES, method=TemplateMethod(tuning={"margin": 0.25}), bones=2)
    np.testing.assert_allclose(sorted([skeleton.heads[0, 1], skeleton.tails[-1, 1]]), [1.0, 3.0])


def test_stages_must_be_typed():
    with pytest.raises(ValueError, match="stage 'axis' is a ndarray, not a rigger.core.stages.Stage"):
        Skeleton(["a"], [(0, 0, 0)], [(0, 0, 1)], [-1], stages={"axis": np.zeros(3)})


def test_a_package_method_may_define_its_class_in_a_module_of_its_own(tmp_path):
    write_package(tmp_path, "up", {"__init__.py": "from .method import Up\n",
                                   "method.py": package_method("up", "")["__init__.py"].replace(
                                       "from .height import HEIGHT", "HEIGHT = 3.0")})
    assert list(discover(tmp_path).methods) == ["up"]


def test_a_tuning_table_made_before_discovery_reloaded_the_method_is_taken():
    from rigger.methods.silhouette.tuning import Tuning  # the class as imported now; discovery loads it afresh

    silhouette = discover().methods["silhouette"]
    assert silhouette.tuning_type is not Tuning
    method = silhouette(tuning=Tuning(longest_bone=1.0))
    assert isinstance(method.tuning, silhouette.tuning_type) and method.tuning.longest_bone == 1.0
    import rigger.methods
    assert rigger.methods.silhouette.SilhouetteMethod is silhouette  # the package attribute is the fresh module


def test_a_changed_tuning_value_reaches_the_rig():
    """No bone longer than ``longest_bone`` bone lengths: at 1.0 instead of 3.0 the long straight box (4 long,
    bone length 0.1 x 4 = 0.4) gets at least ten bones, more than by default."""
    silhouette = discover().methods["silhouette"]
    default = rigger.rig_mesh(BOX_VERTICES, BOX_TRIANGLES, max_chain_bones=1)
    short = rigger.rig_mesh(BOX_VERTICES, BOX_TRIANGLES, method=silhouette(tuning={"longest_bone": 1.0}),
                            max_chain_bones=1)
    assert len(short) > len(default)
    assert np.linalg.norm(short.tails - short.heads, axis=1).max() <= 0.4 + 1e-9
