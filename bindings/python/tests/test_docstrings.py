"""Every public name of amscr (amscr.__all__) is documented: functions, classes, their public
methods, properties and options have a docstring; a function's names every parameter and says
what it returns (unless None) and what it raises (when it takes arguments)."""
import inspect
import re
import typing

import numpy as np
import pytest

import amscr


def _public_callables():
    """(qualified name, object, docstring holder) for every public function, class, method and property."""
    out = []
    for name in amscr.__all__:
        obj = getattr(amscr, name)
        if inspect.isclass(obj):
            out.append((name, obj, obj))
            for attr, member in vars(obj).items():
                if attr.startswith('_') and attr != '__init__':
                    continue
                if isinstance(member, (staticmethod, classmethod)):
                    member = member.__func__
                if isinstance(member, property):
                    out.append(('%s.%s' % (name, attr), None, member.fget))
                elif inspect.isdatadescriptor(member):  # e.g. the options of Params
                    out.append(('%s.%s' % (name, attr), None, member))
                elif inspect.isfunction(member):
                    # __init__ may be documented in the class docstring (the numpy/Google style)
                    out.append(('%s.%s' % (name, attr), member, obj if attr == '__init__' else member))
        elif inspect.isfunction(obj):
            out.append((name, obj, obj))
    return out


CALLABLES = _public_callables()


def _parameters(fn):
    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):
        return []
    return [p.name for p in sig.parameters.values() if p.name not in ('self', 'cls')]


def test_the_walk_finds_the_api():
    names = {n for n, _, _ in CALLABLES}
    assert {'register', 'Registration.apply', 'Collection.query', 'Shape.points', 'Params.copy',
            'as_points', 'GMM1D.fit', 'Params.points', 'AmscrError.__init__'} <= names


def _doc(name, obj, holder):
    doc = inspect.getdoc(holder) or ''
    if name.endswith('.__init__'):  # the class docstring and __init__'s own
        doc += '\n' + (inspect.getdoc(obj) or '')
    return doc


def _returns_something(fn):
    ann = inspect.signature(fn).return_annotation
    return ann not in (None, 'None', inspect.Signature.empty)


@pytest.mark.parametrize('name,obj,holder', CALLABLES, ids=[n for n, _, _ in CALLABLES])
def test_public_name_is_documented(name, obj, holder):
    doc = _doc(name, obj, holder)
    assert doc.strip(), '%s has no docstring' % name
    if obj is None or inspect.isclass(obj):
        return  # a property (documented), or a class (its __init__ is checked as Class.__init__)
    params = _parameters(obj)
    missing = [p for p in params if not re.search(r'\b%s\b' % re.escape(p), doc)]
    assert not missing, '%s: the docstring does not mention %s' % (name, ', '.join(missing))
    is_init = name.endswith('.__init__')
    if _returns_something(obj) and not is_init:
        assert re.search(r'\breturns?\b', doc, re.I), '%s: the docstring does not say what it returns' % name
    if params and not (is_init and issubclass(getattr(amscr, name.split('.')[0]), Exception)):
        assert re.search(r'\braises?\b', doc, re.I), '%s: the docstring does not say what it raises' % name


def test_ctrl_c_promises_say_a_registration_under_way_returns_first():
    """Ctrl-C cancels a batch call between registrations: one under way is not interrupted."""
    for fn in (amscr.Collection.query, amscr.Collection.distance_matrix):
        doc = ' '.join(inspect.getdoc(fn).split())
        assert 'KeyboardInterrupt: Ctrl-C (a registration under way returns first; at the default points it ' \
               'takes milliseconds)' in doc


def test_collection_docs_say_a_pickled_collection_rebuilds_its_retrieval_index():
    doc = ' '.join(inspect.getdoc(amscr.Collection).split())
    assert 'builds it again on its first retrieval query' in doc and 'send an :class:`Index`' in doc


@pytest.mark.parametrize('name,obj,holder', [c for c in CALLABLES if inspect.isfunction(c[1])],
                         ids=[n for n, o, _ in CALLABLES if inspect.isfunction(o)])
def test_annotations_resolve_at_runtime(name, obj, holder):
    """The package ships py.typed: typing.get_type_hints (pydantic, typeguard, Sphinx) resolves
    every public signature, the aliases' forward references (ImageContour, Shape, os.PathLike)
    included, whichever module the function is in."""
    typing.get_type_hints(obj)


@pytest.mark.parametrize('name,obj,holder', [c for c in CALLABLES if inspect.isfunction(c[1])],
                         ids=[n for n, o, _ in CALLABLES if inspect.isfunction(o)])
def test_public_functions_annotate_their_return(name, obj, holder):
    """mypy --strict refuses a call to an unannotated function ("untyped function in typed context")."""
    assert name.endswith('.__init__') or 'return' in obj.__annotations__, '%s has no return annotation' % name


def test_registration_annotations_match_its_attributes():
    """The attributes' annotations are what the result holds: alternatives a tuple, stages a
    read-only mapping (not a list and a dict a type checker would let one change)."""
    t = np.linspace(0, 1, 40, endpoint=False)
    square = 100 * np.concatenate([np.c_[t, 0 * t], np.c_[1 + 0 * t, t], np.c_[1 - t, 1 + 0 * t], np.c_[0 * t, 1 - t]])
    r = amscr.register(square, square @ np.array([[1.2, 0.3], [0.1, 0.9]]).T + 5)
    hints = typing.get_type_hints(amscr.Registration)
    public = {k for k in vars(r) if not k.startswith('_')}
    assert public <= set(hints), 'not annotated: %s' % sorted(public - set(hints))
    for k in public:
        want = typing.get_origin(hints[k]) or hints[k]
        assert isinstance(getattr(r, k), want), (k, type(getattr(r, k)), hints[k])
