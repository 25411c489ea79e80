//! A minimal YAML document tree with the line of each node, enough for refractiveindex.info
//! material files (built from `yaml-rust2`'s parser events).

use yaml_rust2::parser::{Event, MarkedEventReceiver, Parser};
use yaml_rust2::scanner::{Marker, TScalarStyle};

/// A minimal YAML document tree with the line of each node, enough for material files.
#[derive(Debug)]
pub(super) enum Node {
    Scalar(String, TScalarStyle, usize),
    Seq(Vec<Node>, usize),
    Map(Vec<(String, Node)>, usize),
}

impl Node {
    pub(super) fn line(&self) -> usize {
        match self {
            Node::Scalar(_, _, l) | Node::Seq(_, l) | Node::Map(_, l) => *l,
        }
    }
}

#[derive(Default)]
struct TreeBuilder {
    /// Open containers: (node, pending key for maps).
    stack: Vec<(Node, Option<String>)>,
    root: Option<Node>,
    error: Option<(usize, String)>,
}

impl TreeBuilder {
    fn push_value(&mut self, node: Node) {
        let line = node.line();
        match self.stack.last_mut() {
            None => {
                if self.root.is_none() {
                    self.root = Some(node);
                }
            }
            Some((Node::Seq(items, _), _)) => items.push(node),
            Some((Node::Map(entries, _), pending)) => match pending.take() {
                None => match node {
                    Node::Scalar(key, _, _) => *pending = Some(key),
                    _ => {
                        self.error
                            .get_or_insert((line, "mapping keys must be plain scalars".into()));
                    }
                },
                Some(key) => entries.push((key, node)),
            },
            Some((Node::Scalar(..), _)) => {}
        }
    }
}

impl MarkedEventReceiver for TreeBuilder {
    fn on_event(&mut self, ev: Event, mark: Marker) {
        let line = mark.line();
        match ev {
            Event::Scalar(value, style, _, _) => self.push_value(Node::Scalar(value, style, line)),
            Event::SequenceStart(..) => self.stack.push((Node::Seq(Vec::new(), line), None)),
            Event::MappingStart(..) => self.stack.push((Node::Map(Vec::new(), line), None)),
            Event::SequenceEnd | Event::MappingEnd => {
                if let Some((node, _)) = self.stack.pop() {
                    self.push_value(node);
                }
            }
            Event::Alias(_) => {
                self.error.get_or_insert((
                    line,
                    "YAML aliases are not supported in material files".into(),
                ));
            }
            _ => {}
        }
    }
}

pub(super) fn parse_yaml_tree(text: &str) -> std::result::Result<Node, (usize, String)> {
    let mut builder = TreeBuilder::default();
    let mut parser = Parser::new_from_str(text);
    parser
        .load(&mut builder, false)
        .map_err(|e| (e.marker().line(), format!("malformed YAML: {}", e.info())))?;
    if let Some(e) = builder.error {
        return Err(e);
    }
    builder.root.ok_or_else(|| {
        (
            1,
            "empty document: expected a mapping with a `DATA` key".into(),
        )
    })
}
