//! The MCP request handler: lists and calls the tools, and serves the prompt card. A
//! request of the wrong shape (unknown tool, missing or mistyped argument) is a protocol
//! error; a tool that ran and failed (a refused path, a program with errors, a failed run)
//! is a result marked as an error, with its message for the agent to read.

use super::args::{self, RunArgs};
use super::calls;
use super::paths::OutDir;
use super::run::Runner;
use super::tools::{CARD_PROMPT, CARD_URI, LIBRARY_URI, tools};
use rmcp::model::{
    CallToolRequestParams, CallToolResponse, CallToolResult, ContentBlock, GetPromptRequestParams,
    GetPromptResponse, GetPromptResult, Implementation, ListPromptsResult, ListResourcesResult,
    ListToolsResult, PaginatedRequestParams, Prompt, PromptMessage, ReadResourceRequestParams,
    ReadResourceResponse, ReadResourceResult, Resource, ResourceContents, Role, ServerCapabilities,
    ServerConfig,
};
use rmcp::service::RequestContext;
use rmcp::{ErrorData as McpError, RoleServer, ServerHandler};
use serde_json::Value;
use std::sync::Arc;

/// The server's state: where files go and how runs are made.
#[derive(Clone)]
pub struct Server {
    pub(super) out: OutDir,
    pub(super) runner: Arc<Runner>,
    /// The prompt card (with the model's actions when the CLI knows them).
    pub(super) card: Arc<String>,
    /// Far-prompt warnings for `check` (see [`super::Config::far_prompts`]).
    pub(super) far_prompts: Option<Arc<crate::lang::PromptReport>>,
    /// Unseen-pose warnings for `check` (see [`super::Config::coverage`]).
    pub(super) coverage: Option<Arc<crate::coverage::Coverage>>,
}

fn text_result(v: &Value, error: bool) -> CallToolResult {
    let text = serde_json::to_string_pretty(v).unwrap_or_default();
    let mut r = if error {
        CallToolResult::error(vec![ContentBlock::text(text)])
    } else {
        CallToolResult::success(vec![ContentBlock::text(text)])
    };
    r.structured_content = Some(v.clone());
    r
}

impl Server {
    /// Answers one tool call. Err: the request is malformed.
    pub async fn call(
        &self,
        name: &str,
        arguments: Option<&serde_json::Map<String, Value>>,
        cancelled: impl std::future::Future<Output = ()>,
    ) -> Result<CallToolResult, McpError> {
        let a = args::object(arguments);
        let bad = |m: String| McpError::invalid_params(m, None);
        Ok(match name {
            "check" => {
                let source = args::source(&a).map_err(bad)?;
                let set = args::settings(&a, "set").map_err(bad)?;
                let far = self.far_prompts.as_deref();
                let cov = self.coverage.as_deref();
                text_result(&calls::check(&source, &set, far, cov), false)
            }
            "score" => {
                let source = args::source(&a).map_err(bad)?;
                let motion = args::motion(&a).map_err(bad)?;
                let set = args::settings(&a, "set").map_err(bad)?;
                let out = self.out.clone();
                let r =
                    tokio::task::spawn_blocking(move || calls::score(&out, &source, &motion, &set))
                        .await
                        .map_err(|e| McpError::internal_error(format!("score: {e}"), None))?;
                match r {
                    Ok(v) => text_result(&v, false),
                    Err(v) => text_result(&v, true),
                }
            }
            "run" => {
                let run: RunArgs = args::run(&a).map_err(bad)?;
                match self.runner.run(&self.out, run, cancelled).await {
                    Ok(done) => {
                        let mut r = text_result(&done.report, false);
                        if let Some(png) = done.png {
                            r.content.push(ContentBlock::image(png, "image/png"));
                        }
                        r
                    }
                    Err(v) => text_result(&v, true),
                }
            }
            "joints" => text_result(&calls::joints(), false),
            "library" => CallToolResult::success(vec![ContentBlock::text(calls::library())]),
            other => {
                return Err(bad(format!(
                    "unknown tool `{}`; the tools are check, score, run, joints, library",
                    other.escape_debug()
                )));
            }
        })
    }
}

impl ServerHandler for Server {
    fn get_info(&self) -> ServerConfig {
        ServerConfig::new(
            ServerCapabilities::builder()
                .enable_tools()
                .enable_prompts()
                .enable_resources()
                .build(),
        )
        .with_server_info(Implementation::new("mprog", env!("CARGO_PKG_VERSION")))
        .with_instructions(
            "mprog turns .mprog programs (constraints on a human motion) into motions. Read the \
             prompt card (prompt `write-mprog`, resource mprog://prompt-card), write a program, \
             `check` it until it has no errors, then `run` it and look at the errors and the \
             picture. Files go to the server's output folder, named by relative paths.",
        )
    }

    async fn list_tools(
        &self,
        _request: Option<PaginatedRequestParams>,
        _context: RequestContext<RoleServer>,
    ) -> Result<ListToolsResult, McpError> {
        Ok(ListToolsResult::with_all_items(tools()))
    }

    async fn call_tool(
        &self,
        request: CallToolRequestParams,
        context: RequestContext<RoleServer>,
    ) -> Result<CallToolResponse, McpError> {
        let ct = context.ct.clone();
        self.call(
            &request.name,
            request.arguments.as_ref(),
            ct.cancelled_owned(),
        )
        .await
        .map(CallToolResponse::from)
    }

    async fn list_prompts(
        &self,
        _request: Option<PaginatedRequestParams>,
        _context: RequestContext<RoleServer>,
    ) -> Result<ListPromptsResult, McpError> {
        Ok(ListPromptsResult::with_all_items(vec![Prompt::new(
            CARD_PROMPT,
            Some(
                "How to write .mprog programs: the language, the skeleton, the library, worked examples and rules",
            ),
            None,
        )]))
    }

    async fn get_prompt(
        &self,
        request: GetPromptRequestParams,
        _context: RequestContext<RoleServer>,
    ) -> Result<GetPromptResponse, McpError> {
        if request.name != CARD_PROMPT {
            return Err(McpError::invalid_params(
                format!(
                    "unknown prompt `{}`; the prompt is {CARD_PROMPT}",
                    request.name.escape_debug()
                ),
                None,
            ));
        }
        let card = self.card.as_str().to_string();
        Ok(GetPromptResult::new(vec![PromptMessage::new_text(Role::User, card)]).into())
    }

    async fn list_resources(
        &self,
        _request: Option<PaginatedRequestParams>,
        _context: RequestContext<RoleServer>,
    ) -> Result<ListResourcesResult, McpError> {
        Ok(ListResourcesResult::with_all_items(vec![
            Resource::new(CARD_URI, "prompt card")
                .with_description("the system prompt for writing .mprog programs (`mprog prompt`)")
                .with_mime_type("text/markdown"),
            Resource::new(LIBRARY_URI, "library reference")
                .with_description("every builtin and standard-library function")
                .with_mime_type("text/markdown"),
        ]))
    }

    async fn read_resource(
        &self,
        request: ReadResourceRequestParams,
        _context: RequestContext<RoleServer>,
    ) -> Result<ReadResourceResponse, McpError> {
        let text = match request.uri.as_str() {
            CARD_URI => self.card.as_str().to_string(),
            LIBRARY_URI => calls::library(),
            other => {
                return Err(McpError::resource_not_found(
                    format!("no resource `{}`", other.escape_debug()),
                    None,
                ));
            }
        };
        Ok(ReadResourceResult::new(vec![
            ResourceContents::text(text, request.uri.clone()).with_mime_type("text/markdown"),
        ])
        .into())
    }
}
