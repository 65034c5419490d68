//! A serde `Serializer` that builds Python objects directly: the dicts,
//! lists, ints, floats, strings and `None` that `json.loads` makes of
//! serde_json's text for the same value, without writing or parsing any
//! text.
//!
//! It follows serde_json's data model, not Python's: tuples become lists
//! (JSON has no tuple), a float that is not finite becomes `None` (serde_json
//! writes `null`), map keys become strings as serde_json writes them, enum
//! variants take serde_json's externally tagged form. Keys are interned
//! for the whole conversion (as `json.loads` memoises them): an answer with
//! proofs is mostly a few key names repeated hundreds of thousands of times,
//! and one Python string per distinct key saves both the building and the
//! memory. Dict keys come in the value's serialisation order.

use pyo3::IntoPyObjectExt;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyList, PyString};
use serde::Serialize;
use serde::ser::{self, Impossible};
use std::collections::HashMap;

/// `value` as Python objects.
pub(crate) fn to_python<'py, T: Serialize + ?Sized>(
    py: Python<'py>,
    value: &T,
) -> PyResult<Bound<'py, PyAny>> {
    let mut keys = Keys {
        py,
        seen: HashMap::new(),
    };
    value.serialize(ToPy { keys: &mut keys }).map_err(|e| e.0)
}

/// The error of a conversion: a Python exception (from building an
/// object, or a serde error as `ValueError`).
#[derive(Debug)]
pub(crate) struct Error(PyErr);

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl std::error::Error for Error {}

impl ser::Error for Error {
    fn custom<T: std::fmt::Display>(msg: T) -> Error {
        Error(PyValueError::new_err(msg.to_string()))
    }
}

impl From<std::convert::Infallible> for Error {
    fn from(e: std::convert::Infallible) -> Error {
        match e {}
    }
}

impl From<PyErr> for Error {
    fn from(e: PyErr) -> Error {
        Error(e)
    }
}

type Result<T> = std::result::Result<T, Error>;

/// The interned keys of one conversion.
struct Keys<'py> {
    py: Python<'py>,
    seen: HashMap<String, Bound<'py, PyString>>,
}

impl<'py> Keys<'py> {
    fn get(&mut self, key: &str) -> Bound<'py, PyString> {
        if let Some(k) = self.seen.get(key) {
            return k.clone();
        }
        let k = PyString::new(self.py, key);
        self.seen.insert(key.to_string(), k.clone());
        k
    }
}

/// Every integer method of a serde `Serializer`, each `self.$how(v)`.
macro_rules! ints {
    ($how:ident) => {
        ints!($how: serialize_i8 i8, serialize_i16 i16, serialize_i32 i32, serialize_i64 i64,
            serialize_i128 i128, serialize_u8 u8, serialize_u16 u16, serialize_u32 u32,
            serialize_u64 u64, serialize_u128 u128);
    };
    ($how:ident: $($method:ident $t:ty),*) => {$(
        fn $method(self, v: $t) -> Result<Self::Ok> {
            self.$how(v)
        }
    )*};
}

/// The serializer of one value.
struct ToPy<'a, 'py> {
    keys: &'a mut Keys<'py>,
}

impl<'a, 'py> ToPy<'a, 'py> {
    fn py(&self) -> Python<'py> {
        self.keys.py
    }

    /// An integer as a Python `int`.
    fn into_int<I: IntoPyObject<'py>>(self, v: I) -> Result<Bound<'py, PyAny>> {
        Ok(v.into_bound_py_any(self.py())?)
    }

    /// `{variant: value}`, serde_json's form of a variant with data.
    fn tagged(self, variant: &'static str, value: Bound<'py, PyAny>) -> Result<Bound<'py, PyAny>> {
        let d = PyDict::new(self.py());
        d.set_item(self.keys.get(variant), value)?;
        Ok(d.into_any())
    }
}

/// A list being built (sequences, tuples, a tuple variant's fields).
struct Seq<'a, 'py> {
    keys: &'a mut Keys<'py>,
    list: Bound<'py, PyList>,
    /// A tuple variant's name: the list is wrapped as `{variant: list}`.
    variant: Option<&'static str>,
}

/// A dict being built (maps, structs, a struct variant's fields).
struct Map<'a, 'py> {
    keys: &'a mut Keys<'py>,
    dict: Bound<'py, PyDict>,
    key: Option<Bound<'py, PyString>>,
    /// A struct variant's name: the dict is wrapped as `{variant: dict}`.
    variant: Option<&'static str>,
}

impl<'a, 'py> Seq<'a, 'py> {
    fn push<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<()> {
        let v = value.serialize(ToPy {
            keys: &mut *self.keys,
        })?;
        self.list.append(v)?;
        Ok(())
    }

    fn done(self) -> Result<Bound<'py, PyAny>> {
        match self.variant {
            None => Ok(self.list.into_any()),
            Some(name) => ToPy { keys: self.keys }.tagged(name, self.list.into_any()),
        }
    }
}

impl<'a, 'py> Map<'a, 'py> {
    fn entry<T: Serialize + ?Sized>(&mut self, key: Bound<'py, PyString>, value: &T) -> Result<()> {
        let v = value.serialize(ToPy {
            keys: &mut *self.keys,
        })?;
        self.dict.set_item(key, v)?;
        Ok(())
    }

    fn done(self) -> Result<Bound<'py, PyAny>> {
        match self.variant {
            None => Ok(self.dict.into_any()),
            Some(name) => ToPy { keys: self.keys }.tagged(name, self.dict.into_any()),
        }
    }
}

impl<'a, 'py> ser::Serializer for ToPy<'a, 'py> {
    type Ok = Bound<'py, PyAny>;
    type Error = Error;
    type SerializeSeq = Seq<'a, 'py>;
    type SerializeTuple = Seq<'a, 'py>;
    type SerializeTupleStruct = Seq<'a, 'py>;
    type SerializeTupleVariant = Seq<'a, 'py>;
    type SerializeMap = Map<'a, 'py>;
    type SerializeStruct = Map<'a, 'py>;
    type SerializeStructVariant = Map<'a, 'py>;

    fn serialize_bool(self, v: bool) -> Result<Self::Ok> {
        Ok(PyBool::new(self.py(), v).to_owned().into_any())
    }
    ints!(into_int);
    fn serialize_f32(self, v: f32) -> Result<Self::Ok> {
        // serde_json writes an f32 by its shortest decimal, which Python
        // reads back as that decimal, not as the f32 widened.
        match v.is_finite() {
            true => self.serialize_f64(v.to_string().parse().unwrap_or(f64::from(v))),
            false => self.serialize_none(),
        }
    }
    fn serialize_f64(self, v: f64) -> Result<Self::Ok> {
        match v.is_finite() {
            true => Ok(PyFloat::new(self.py(), v).into_any()),
            false => self.serialize_none(),
        }
    }
    fn serialize_char(self, v: char) -> Result<Self::Ok> {
        self.serialize_str(v.encode_utf8(&mut [0; 4]))
    }
    fn serialize_str(self, v: &str) -> Result<Self::Ok> {
        Ok(PyString::new(self.py(), v).into_any())
    }
    fn serialize_bytes(self, v: &[u8]) -> Result<Self::Ok> {
        use ser::SerializeSeq;
        let mut s = self.serialize_seq(Some(v.len()))?;
        for b in v {
            s.serialize_element(b)?;
        }
        s.end()
    }
    fn serialize_none(self) -> Result<Self::Ok> {
        Ok(self.py().None().into_bound(self.py()))
    }
    fn serialize_some<T: Serialize + ?Sized>(self, value: &T) -> Result<Self::Ok> {
        value.serialize(self)
    }
    fn serialize_unit(self) -> Result<Self::Ok> {
        self.serialize_none()
    }
    fn serialize_unit_struct(self, _name: &'static str) -> Result<Self::Ok> {
        self.serialize_none()
    }
    fn serialize_unit_variant(
        self,
        _name: &'static str,
        _index: u32,
        variant: &'static str,
    ) -> Result<Self::Ok> {
        Ok(self.keys.get(variant).into_any())
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _name: &'static str,
        value: &T,
    ) -> Result<Self::Ok> {
        value.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _name: &'static str,
        _index: u32,
        variant: &'static str,
        value: &T,
    ) -> Result<Self::Ok> {
        let v = value.serialize(ToPy {
            keys: &mut *self.keys,
        })?;
        self.tagged(variant, v)
    }
    fn serialize_seq(self, _len: Option<usize>) -> Result<Seq<'a, 'py>> {
        Ok(Seq {
            list: PyList::empty(self.py()),
            keys: self.keys,
            variant: None,
        })
    }
    fn serialize_tuple(self, len: usize) -> Result<Seq<'a, 'py>> {
        self.serialize_seq(Some(len))
    }
    fn serialize_tuple_struct(self, _name: &'static str, len: usize) -> Result<Seq<'a, 'py>> {
        self.serialize_seq(Some(len))
    }
    fn serialize_tuple_variant(
        self,
        _name: &'static str,
        _index: u32,
        variant: &'static str,
        len: usize,
    ) -> Result<Seq<'a, 'py>> {
        let mut s = self.serialize_seq(Some(len))?;
        s.variant = Some(variant);
        Ok(s)
    }
    fn serialize_map(self, _len: Option<usize>) -> Result<Map<'a, 'py>> {
        Ok(Map {
            dict: PyDict::new(self.py()),
            keys: self.keys,
            key: None,
            variant: None,
        })
    }
    fn serialize_struct(self, _name: &'static str, len: usize) -> Result<Map<'a, 'py>> {
        self.serialize_map(Some(len))
    }
    fn serialize_struct_variant(
        self,
        _name: &'static str,
        _index: u32,
        variant: &'static str,
        len: usize,
    ) -> Result<Map<'a, 'py>> {
        let mut m = self.serialize_map(Some(len))?;
        m.variant = Some(variant);
        Ok(m)
    }
}

/// The serde traits of a list being built, each pushing an item (a
/// sequence's element, a tuple's field…).
macro_rules! seq_impls {
    ($($trait:ident :: $method:ident),*) => {$(
        impl<'py> ser::$trait for Seq<'_, 'py> {
            type Ok = Bound<'py, PyAny>;
            type Error = Error;
            fn $method<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<()> {
                self.push(value)
            }
            fn end(self) -> Result<Self::Ok> {
                self.done()
            }
        }
    )*};
}

seq_impls!(
    SerializeSeq::serialize_element,
    SerializeTuple::serialize_element,
    SerializeTupleStruct::serialize_field,
    SerializeTupleVariant::serialize_field
);

impl<'py> ser::SerializeMap for Map<'_, 'py> {
    type Ok = Bound<'py, PyAny>;
    type Error = Error;
    fn serialize_key<T: Serialize + ?Sized>(&mut self, key: &T) -> Result<()> {
        self.key = Some(key.serialize(KeyText {
            keys: &mut *self.keys,
        })?);
        Ok(())
    }
    fn serialize_value<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<()> {
        let key = self
            .key
            .take()
            .ok_or_else(|| <Error as ser::Error>::custom("a map value without its key"))?;
        self.entry(key, value)
    }
    fn end(self) -> Result<Self::Ok> {
        self.done()
    }
}

/// The serde traits of a dict being built from named fields.
macro_rules! struct_impls {
    ($($trait:ident),*) => {$(
        impl<'py> ser::$trait for Map<'_, 'py> {
            type Ok = Bound<'py, PyAny>;
            type Error = Error;
            fn serialize_field<T: Serialize + ?Sized>(
                &mut self,
                key: &'static str,
                value: &T,
            ) -> Result<()> {
                let key = self.keys.get(key);
                self.entry(key, value)
            }
            fn end(self) -> Result<Self::Ok> {
                self.done()
            }
        }
    )*};
}

struct_impls!(SerializeStruct, SerializeStructVariant);

/// A map key as the (interned) string serde_json writes for it: a string
/// as it is, a number or bool in decimal, a unit variant by name; anything
/// else is refused, as serde_json refuses it.
struct KeyText<'a, 'py> {
    keys: &'a mut Keys<'py>,
}

impl<'py> KeyText<'_, 'py> {
    fn text(self, v: impl ToString) -> Result<Bound<'py, PyString>> {
        Ok(self.keys.get(&v.to_string()))
    }
}

fn key_must_be_a_string() -> Error {
    <Error as ser::Error>::custom("key must be a string")
}

impl<'py> ser::Serializer for KeyText<'_, 'py> {
    type Ok = Bound<'py, PyString>;
    type Error = Error;
    type SerializeSeq = Impossible<Bound<'py, PyString>, Error>;
    type SerializeTuple = Impossible<Bound<'py, PyString>, Error>;
    type SerializeTupleStruct = Impossible<Bound<'py, PyString>, Error>;
    type SerializeTupleVariant = Impossible<Bound<'py, PyString>, Error>;
    type SerializeMap = Impossible<Bound<'py, PyString>, Error>;
    type SerializeStruct = Impossible<Bound<'py, PyString>, Error>;
    type SerializeStructVariant = Impossible<Bound<'py, PyString>, Error>;

    fn serialize_str(self, v: &str) -> Result<Self::Ok> {
        Ok(self.keys.get(v))
    }
    fn serialize_bool(self, v: bool) -> Result<Self::Ok> {
        self.text(v)
    }
    ints!(text);
    fn serialize_f32(self, _v: f32) -> Result<Self::Ok> {
        Err(key_must_be_a_string())
    }
    fn serialize_f64(self, _v: f64) -> Result<Self::Ok> {
        Err(key_must_be_a_string())
    }
    fn serialize_char(self, v: char) -> Result<Self::Ok> {
        self.text(v)
    }
    fn serialize_bytes(self, _v: &[u8]) -> Result<Self::Ok> {
        Err(key_must_be_a_string())
    }
    fn serialize_none(self) -> Result<Self::Ok> {
        Err(key_must_be_a_string())
    }
    fn serialize_some<T: Serialize + ?Sized>(self, _value: &T) -> Result<Self::Ok> {
        Err(key_must_be_a_string())
    }
    fn serialize_unit(self) -> Result<Self::Ok> {
        Err(key_must_be_a_string())
    }
    fn serialize_unit_struct(self, _name: &'static str) -> Result<Self::Ok> {
        Err(key_must_be_a_string())
    }
    fn serialize_unit_variant(
        self,
        _name: &'static str,
        _index: u32,
        variant: &'static str,
    ) -> Result<Self::Ok> {
        Ok(self.keys.get(variant))
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _name: &'static str,
        value: &T,
    ) -> Result<Self::Ok> {
        value.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _name: &'static str,
        _index: u32,
        _variant: &'static str,
        _value: &T,
    ) -> Result<Self::Ok> {
        Err(key_must_be_a_string())
    }
    fn serialize_seq(self, _len: Option<usize>) -> Result<Self::SerializeSeq> {
        Err(key_must_be_a_string())
    }
    fn serialize_tuple(self, _len: usize) -> Result<Self::SerializeTuple> {
        Err(key_must_be_a_string())
    }
    fn serialize_tuple_struct(
        self,
        _name: &'static str,
        _len: usize,
    ) -> Result<Self::SerializeTupleStruct> {
        Err(key_must_be_a_string())
    }
    fn serialize_tuple_variant(
        self,
        _name: &'static str,
        _index: u32,
        _variant: &'static str,
        _len: usize,
    ) -> Result<Self::SerializeTupleVariant> {
        Err(key_must_be_a_string())
    }
    fn serialize_map(self, _len: Option<usize>) -> Result<Self::SerializeMap> {
        Err(key_must_be_a_string())
    }
    fn serialize_struct(self, _name: &'static str, _len: usize) -> Result<Self::SerializeStruct> {
        Err(key_must_be_a_string())
    }
    fn serialize_struct_variant(
        self,
        _name: &'static str,
        _index: u32,
        _variant: &'static str,
        _len: usize,
    ) -> Result<Self::SerializeStructVariant> {
        Err(key_must_be_a_string())
    }
}
