//! A call's arguments as one flat tree: every value in one vector, each object's members and
//! each array's elements in one contiguous run of another, member names borrowed from the
//! registry tables. Decoding a binary call fills it without an allocation per value, and one
//! tree is reused call after call; the JSON routes convert their parsed values into it, so
//! the importer reads all three routes through the same `Arg`. JSON text goes straight in
//! through [`Put`], without a `serde_json::Value` on the way, so a line costs its tree only.

use std::fmt;

use serde::de::{self, DeserializeSeed, Deserializer, MapAccess, SeqAccess, Visitor};
use serde_json::Value;

use super::gfxr::registry::ENUMS;

/// A text: borrowed from the tables (member and enumerant names) or held in the tree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Text {
    Static(&'static str),
    Held { start: usize, len: usize },
}

/// A contiguous run of members or elements in the tree's `kids`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Run {
    start: usize,
    len: usize,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Node {
    Null,
    Bool(bool),
    U64(u64),
    /// Negative integers only: non-negative ones are `U64`, as `serde_json` keeps them.
    I64(i64),
    F64(f64),
    Str(Text),
    Object(Run),
    Array(Run),
    /// An enumerant of the registry's enum `table`, as decoded: given out as its name (a
    /// `Str`), or as a number where the table does not know it. Named only when read, since
    /// most are never read (every structure's `sType`).
    Enum {
        table: u16,
        value: i32,
    },
}

/// One member of an object (named) or element of an array (`key` unused).
#[derive(Clone, Copy, Debug)]
pub struct Kid {
    pub key: Text,
    pub node: usize,
}

const NO_KEY: Text = Text::Static("");

#[derive(Debug, Default)]
pub struct Tree {
    nodes: Vec<Node>,
    kids: Vec<Kid>,
    text: String,
    /// Members and elements of the objects and arrays being built, innermost last.
    open: Vec<Kid>,
    root: Option<usize>,
}

impl Tree {
    /// Empties the tree, keeping its storage for the next call.
    pub fn clear(&mut self) {
        self.nodes.clear();
        self.kids.clear();
        self.text.clear();
        self.open.clear();
        self.root = None;
    }

    pub fn leaf(&mut self, node: Node) -> usize {
        self.nodes.push(node);
        self.nodes.len() - 1
    }

    pub fn hold(&mut self, s: &str) -> Text {
        let start = self.text.len();
        self.text.push_str(s);
        Text::Held {
            start,
            len: s.len(),
        }
    }

    pub fn string(&mut self, s: &str) -> usize {
        let t = self.hold(s);
        self.leaf(Node::Str(t))
    }

    /// Where the members or elements of a new object or array begin.
    pub fn mark(&self) -> usize {
        self.open.len()
    }

    pub fn member(&mut self, key: Text, node: usize) {
        self.open.push(Kid { key, node });
    }

    pub fn element(&mut self, node: usize) {
        self.open.push(Kid { key: NO_KEY, node });
    }

    fn close(&mut self, mark: usize) -> Run {
        let start = self.kids.len();
        self.kids.extend(self.open.drain(mark..));
        Run {
            start,
            len: self.kids.len() - start,
        }
    }

    /// The object of the members given since `mark`.
    pub fn object(&mut self, mark: usize) -> usize {
        let run = self.close(mark);
        self.leaf(Node::Object(run))
    }

    /// The array of the elements given since `mark`.
    pub fn array(&mut self, mark: usize) -> usize {
        let run = self.close(mark);
        self.leaf(Node::Array(run))
    }

    pub fn set_root(&mut self, node: usize) {
        self.root = Some(node);
    }

    /// The root; an empty tree reads as null.
    pub fn root(&self) -> usize {
        self.root.unwrap_or(usize::MAX)
    }

    pub fn node(&self, i: usize) -> Node {
        match self.nodes.get(i) {
            Some(Node::Enum { table, value }) => {
                match ENUMS
                    .get(usize::from(*table))
                    .and_then(|d| d.name_of(*value))
                {
                    Some(name) => Node::Str(Text::Static(name)),
                    None => int(i64::from(*value)),
                }
            }
            Some(n) => *n,
            None => Node::Null,
        }
    }

    pub fn text(&self, t: Text) -> &str {
        match t {
            Text::Static(s) => s,
            Text::Held { start, len } => self.text.get(start..start + len).unwrap_or(""),
        }
    }

    pub fn kids(&self, run: Run) -> &[Kid] {
        self.kids.get(run.start..run.start + run.len).unwrap_or(&[])
    }

    /// Member `key` of object `i`.
    pub fn get(&self, i: usize, key: &str) -> Option<usize> {
        match self.node(i) {
            // Length and last byte first: few members of one structure share both, so most
            // members passed over cost no comparison call.
            Node::Object(run) => self
                .kids(run)
                .iter()
                .find(|k| {
                    let t = self.text(k.key);
                    t.len() == key.len() && t.as_bytes().last() == key.as_bytes().last() && t == key
                })
                .map(|k| k.node),
            _ => None,
        }
    }

    /// A tree holding `value`.
    pub fn from_json(value: &Value) -> Tree {
        let mut t = Tree::default();
        let root = t.put(value);
        t.set_root(root);
        t
    }

    fn put(&mut self, value: &Value) -> usize {
        match value {
            Value::Null => self.leaf(Node::Null),
            Value::Bool(b) => self.leaf(Node::Bool(*b)),
            Value::Number(n) => self.leaf(match (n.as_u64(), n.as_i64()) {
                (Some(u), _) => Node::U64(u),
                (None, Some(i)) => Node::I64(i),
                _ => Node::F64(n.as_f64().unwrap_or(f64::NAN)),
            }),
            Value::String(s) => self.string(s),
            Value::Array(items) => {
                let mark = self.mark();
                for v in items {
                    let n = self.put(v);
                    self.element(n);
                }
                self.array(mark)
            }
            Value::Object(map) => {
                let mark = self.mark();
                for (k, v) in map {
                    let n = self.put(v);
                    let key = self.hold(k);
                    self.member(key, n);
                }
                self.object(mark)
            }
        }
    }

    /// The first member name that object run `run` repeats; sorted rather than compared
    /// pairwise, so an object of a million members costs no more than sorting them.
    fn repeated(&self, run: Run) -> Option<&str> {
        let kids = self.kids(run);
        if kids.len() < 2 {
            return None;
        }
        let mut names: Vec<&str> = kids.iter().map(|k| self.text(k.key)).collect();
        names.sort_unstable();
        names.windows(2).find(|w| w[0] == w[1]).map(|w| w[0])
    }

    /// Node `i` as JSON, members in name order as `serde_json` keeps them.
    pub fn to_json(&self, i: usize) -> Value {
        match self.node(i) {
            Node::Null => Value::Null,
            Node::Bool(b) => Value::Bool(b),
            Node::U64(u) => Value::from(u),
            Node::I64(v) => Value::from(v),
            Node::F64(f) => Value::from(f),
            Node::Str(t) => Value::from(self.text(t)),
            Node::Array(run) => Value::Array(
                self.kids(run)
                    .iter()
                    .map(|k| self.to_json(k.node))
                    .collect(),
            ),
            // `node` never gives an enumerant out as such.
            Node::Enum { value, .. } => Value::from(value),
            Node::Object(run) => Value::Object(
                self.kids(run)
                    .iter()
                    .map(|k| (self.text(k.key).to_owned(), self.to_json(k.node)))
                    .collect(),
            ),
        }
    }
}

/// Puts one JSON value, read from a `serde_json` deserializer, into the tree, giving its node.
/// Numbers are kept as `serde_json` keeps them; an object that names a member twice is
/// refused (a `serde_json::Value` would have kept the last silently).
pub struct Put<'t>(pub &'t mut Tree);

impl<'de> DeserializeSeed<'de> for Put<'_> {
    type Value = usize;

    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<usize, D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> Visitor<'de> for Put<'_> {
    type Value = usize;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a JSON value")
    }

    fn visit_bool<E>(self, v: bool) -> Result<usize, E> {
        Ok(self.0.leaf(Node::Bool(v)))
    }

    fn visit_u64<E>(self, v: u64) -> Result<usize, E> {
        Ok(self.0.leaf(Node::U64(v)))
    }

    fn visit_i64<E>(self, v: i64) -> Result<usize, E> {
        Ok(self.0.leaf(int(v)))
    }

    fn visit_f64<E>(self, v: f64) -> Result<usize, E> {
        Ok(self.0.leaf(Node::F64(v)))
    }

    fn visit_str<E>(self, v: &str) -> Result<usize, E> {
        Ok(self.0.string(v))
    }

    fn visit_unit<E>(self) -> Result<usize, E> {
        Ok(self.0.leaf(Node::Null))
    }

    fn visit_none<E>(self) -> Result<usize, E> {
        Ok(self.0.leaf(Node::Null))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<usize, A::Error> {
        let tree = self.0;
        let mark = tree.mark();
        while let Some(n) = seq.next_element_seed(Put(tree))? {
            tree.element(n);
        }
        Ok(tree.array(mark))
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<usize, A::Error> {
        let tree = self.0;
        let mark = tree.mark();
        while let Some(key) = map.next_key_seed(Key(tree))? {
            let n = map.next_value_seed(Put(tree))?;
            tree.member(key, n);
        }
        let node = tree.object(mark);
        if let Node::Object(run) = tree.node(node)
            && let Some(name) = tree.repeated(run)
        {
            return Err(de::Error::custom(format_args!(
                "member `{name}` given twice in one object"
            )));
        }
        Ok(node)
    }
}

/// A member name, held in the tree's text.
struct Key<'t>(&'t mut Tree);

impl<'de> DeserializeSeed<'de> for Key<'_> {
    type Value = Text;

    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Text, D::Error> {
        d.deserialize_str(self)
    }
}

impl<'de> Visitor<'de> for Key<'_> {
    type Value = Text;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a member name")
    }

    fn visit_str<E>(self, v: &str) -> Result<Text, E> {
        Ok(self.0.hold(v))
    }
}

/// An integer as `serde_json` keeps it: non-negative ones unsigned.
pub fn int(v: i64) -> Node {
    match u64::try_from(v) {
        Ok(u) => Node::U64(u),
        Err(_) => Node::I64(v),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn json_goes_in_and_comes_back_unchanged() {
        let v = json!({"a": [1, -2, 2.5, "x", null, true], "b": {"c": {}, "d": []}, "e": u64::MAX});
        let t = Tree::from_json(&v);
        assert_eq!(t.to_json(t.root()), v);
        let b = t.get(t.root(), "b").unwrap();
        assert!(matches!(t.node(t.get(b, "d").unwrap()), Node::Array(_)));
        assert_eq!(t.get(t.root(), "z"), None);
        assert_eq!(Tree::default().node(Tree::default().root()), Node::Null);
    }

    fn parsed(text: &str) -> Result<(Tree, usize), serde_json::Error> {
        let mut t = Tree::default();
        let mut de = serde_json::Deserializer::from_str(text);
        let root = Put(&mut t).deserialize(&mut de)?;
        de.end()?;
        t.set_root(root);
        Ok((t, root))
    }

    #[test]
    fn json_text_goes_in_as_through_a_value() {
        let text = r#"{"z": [1, -2, 2.5, "x\u00e9", null, true, 18446744073709551615],
            "b": {"c": {}, "d": []}, "a": -9223372036854775808}"#;
        let (t, root) = parsed(text).unwrap();
        let v: Value = serde_json::from_str(text).unwrap();
        assert_eq!(t.to_json(root), v);
        assert!(matches!(
            t.node(t.get(root, "a").unwrap()),
            Node::I64(i64::MIN)
        ));
        assert_eq!(
            t.text(match t.node(t.get(root, "z").unwrap()) {
                Node::Array(run) => match t.node(t.kids(run)[3].node) {
                    Node::Str(s) => s,
                    n => panic!("{n:?}"),
                },
                n => panic!("{n:?}"),
            }),
            "x\u{e9}"
        );
    }

    #[test]
    fn a_member_given_twice_is_refused() {
        let e = parsed(r#"{"a": {"k": 1, "j": 2, "k": 3}}"#).unwrap_err();
        assert!(e.to_string().contains("member `k` given twice"), "{e}");
        assert!(parsed(r#"[{"k": 1}, {"k": 2}]"#).is_ok());
        assert!(parsed("[1, 2").unwrap_err().is_eof());
    }

    #[test]
    fn a_cleared_tree_builds_again() {
        let mut t = Tree::from_json(&json!({"a": 1}));
        t.clear();
        let mark = t.mark();
        let one = t.leaf(Node::U64(1));
        t.member(Text::Static("k"), one);
        let s = t.string("v");
        let inner = t.mark();
        t.element(s);
        let arr = t.array(inner);
        t.member(Text::Static("l"), arr);
        let root = t.object(mark);
        t.set_root(root);
        assert_eq!(t.to_json(root), json!({"k": 1, "l": ["v"]}));
    }
}
